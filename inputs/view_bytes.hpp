#pragma once
// A float RGBA view (core/image.hpp) as the bytes a StereoVideoFrame carries: what the drivers
// that make their views as images (the synthetic clip, stills) deliver.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/image.hpp"

namespace nelf {

// Tightly packed RGBA of `bits` per channel (8, or 16: native-endian uint16), clamped to 0..1 and
// rounded to the nearest code value.
std::vector<std::uint8_t> view_bytes(const Image& image, int bits);

// The order of a 4-byte pixel's channels in memory. bgrx: blue, green, red and a byte that is not
// alpha, what X servers and GL drivers keep a window's pixels in (X11's 24-bit visuals on a
// little-endian machine), read as stored.
enum class ByteOrder { rgba, bgrx };

// A view of 8-bit rows as RGBA (width / bx) × (height / by) means of bx × by pixels, each rounded
// to the nearest code value, alpha 255 (1 × 1: the rows copied as they are, RGBA; bgrx: alpha 255): the
// ViewFormat block the compositor negotiated, made while the pixels are in cache (the live
// captures: a window's rows, a game's eyes). `first_row` is the view's top row; rows are
// `row_stride` bytes apart, negative for images stored bottom-up (OpenGL's read-back); `order` is
// how they hold each pixel (the means are reordered, a quarter or less of the bytes).
std::vector<std::uint8_t> rgba8_block_means(const std::uint8_t* first_row, std::ptrdiff_t row_stride, int width,
                                            int height, std::array<int, 2> block, ByteOrder order = ByteOrder::rgba);

}  // namespace nelf
