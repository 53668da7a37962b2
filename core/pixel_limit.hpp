#pragma once
// The largest image or video frame nelf decodes (--max-pixels; DESIGN.md §11 untrusted media). A
// 261 KB PNG can claim 16384x16384 pixels and cost gigabytes to decode: sizes are checked against
// this limit from the file's header, before any pixel is decoded or allocated.
//
// Header only (inline): the image-library module (compositor/oiio/) uses it without linking nelf.
#include <cstdint>
#include <optional>
#include <string>

namespace nelf {

// 2^27 = 134,217,728 pixels: room for an 8K full side-by-side frame (15360x4320 = 66 Mpx), two
// 50 Mpx photos side by side (100 Mpx) and 16384x8192, but not a 16384x16384 bomb (268 Mpx). A
// still at the limit takes about 4 GB while it is read (float RGBA plus the decoder's copy).
inline constexpr std::int64_t kDefaultMaxPixels = std::int64_t{1} << 27;

// Why a `width`x`height` picture is refused under `max_pixels`, or nothing when it fits. The text
// names the size and the option that raises the limit.
inline std::optional<std::string> pixel_limit_problem(std::int64_t width, std::int64_t height,
                                                      std::int64_t max_pixels) {
  const std::int64_t pixels = width * height;  // both at most 2^31 - 1: no overflow
  if (pixels <= max_pixels) return std::nullopt;
  return std::to_string(width) + "x" + std::to_string(height) + " is " + std::to_string(pixels) +
         " pixels, more than the limit of " + std::to_string(max_pixels) + " (--max-pixels raises it)";
}

}  // namespace nelf
