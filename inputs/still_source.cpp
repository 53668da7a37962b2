#include "inputs/still_source.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <system_error>
#include <vector>

#include "core/image_library.hpp"

namespace nelf {
namespace {

namespace fs = std::filesystem;

std::string lowercase_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// Float RGBA from what the image library read (one to four channels).
Image to_rgba(const image_library::Pixels& pixels) {
  Image image(pixels.width, pixels.height);
  const float* src = pixels.values.data();
  const int channels = pixels.channels;
  for (Rgba& px : image.pixels()) {
    switch (channels) {
      case 1:
        px = {src[0], src[0], src[0], 1.f};
        break;
      case 2:  // gray + alpha
        px = {src[0], src[0], src[0], src[1]};
        break;
      case 3:
        px = {src[0], src[1], src[2], 1.f};
        break;
      default:
        px = {src[0], src[1], src[2], src[3]};
        break;
    }
    src += channels;
  }
  return image;
}

std::vector<std::byte> read_bytes(const fs::path& path) {
  constexpr std::uintmax_t kMaxBytes = std::uintmax_t{1} << 30;  // 1 GiB: far beyond any real MPO
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec) throw StillError(fmt::format("{}: cannot read ({})", path.string(), ec.message()));
  if (size > kMaxBytes) throw StillError(fmt::format("{}: file is too large ({} bytes)", path.string(), size));
  std::vector<std::byte> bytes(static_cast<std::size_t>(size));
  std::ifstream file(path, std::ios::binary);
  if (!file.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size())))
    throw StillError(fmt::format("{}: cannot read", path.string()));
  return bytes;
}

void require_file(const fs::path& path) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (!fs::exists(status)) throw StillError(fmt::format("{}: no such file", path.string()));
  if (!fs::is_regular_file(status)) throw StillError(fmt::format("{}: not a regular file", path.string()));
}

std::string size_of(const Image& image) { return fmt::format("{}x{}", image.width(), image.height()); }

View natural_view(Image image) {
  const double aspect = static_cast<double>(image.width()) / static_cast<double>(image.height());
  return View{std::move(image), aspect};
}

StillStereo load_pair(const fs::path& left_path, const fs::path& right_path, const StillOptions& options) {
  Image left = read_image_file(left_path, options.max_pixels);
  Image right = read_image_file(right_path, options.max_pixels);
  if (left.width() != right.width() || left.height() != right.height())
    throw StillError(fmt::format("{} is {} but {} is {}: the two views of a pair must have the same size",
                                 left_path.string(), size_of(left), right_path.string(), size_of(right)));
  StillStereo result{{natural_view(std::move(left)), natural_view(std::move(right))},
                     {StereoLayout::pair, false, DetectionRule::flag, {}}};
  if (options.swap_eyes) std::swap(result.views.left, result.views.right);
  return result;
}

// MPO (CIPA DC-007): the first image is the left view, the second the right one.
StillStereo load_mpo(const fs::path& path, const StillOptions& options) {
  if (options.layout && *options.layout != StereoLayout::pair)
    throw StillError(
        fmt::format("{}: an MPO file holds two separate views; layout {} does not apply (use pair or "
                    "leave --layout out)",
                    path.string(), to_string(*options.layout)));
  const auto bytes = read_bytes(path);
  const auto starts = find_mpo_images(bytes);
  if (starts.size() < 2)
    throw StillError(
        fmt::format("{}: the MPO file holds {} image(s), a stereo pair needs two", path.string(), starts.size()));
  const std::span<const std::byte> all(bytes);
  Image left = decode_image(all.subspan(starts[0], starts[1] - starts[0]), "jpeg", path.string() + " (left image)",
                            options.max_pixels);
  const std::size_t right_end = starts.size() > 2 ? starts[2] : bytes.size();
  Image right = decode_image(all.subspan(starts[1], right_end - starts[1]), "jpeg", path.string() + " (right image)",
                             options.max_pixels);
  if (left.width() != right.width() || left.height() != right.height())
    throw StillError(fmt::format("{}: its left image is {} but its right image is {}", path.string(), size_of(left),
                                 size_of(right)));
  StillStereo result{{natural_view(std::move(left)), natural_view(std::move(right))},
                     {StereoLayout::pair, false, options.layout ? DetectionRule::flag : DetectionRule::metadata, {}}};
  if (options.swap_eyes) std::swap(result.views.left, result.views.right);
  return result;
}

std::uint8_t byte_at(std::span<const std::byte> bytes, std::size_t i) {
  return std::to_integer<std::uint8_t>(bytes[i]);
}

// Index of the next SOI marker followed by another marker (FF D8 FF) at or after `from`.
std::optional<std::size_t> next_soi(std::span<const std::byte> bytes, std::size_t from) {
  for (std::size_t i = from; i + 2 < bytes.size(); ++i)
    if (byte_at(bytes, i) == 0xFF && byte_at(bytes, i + 1) == 0xD8 && byte_at(bytes, i + 2) == 0xFF) return i;
  return std::nullopt;
}

// Given the index just after an SOI, returns the index just after the image's EOI, or nothing when
// the segment structure is broken or truncated. Segments are skipped by their length so that an
// embedded EXIF thumbnail (a whole JPEG inside APP1) is not mistaken for the next image.
std::optional<std::size_t> end_of_jpeg(std::span<const std::byte> bytes, std::size_t p) {
  const std::size_t n = bytes.size();
  while (p < n) {
    if (byte_at(bytes, p) != 0xFF) return std::nullopt;
    while (p < n && byte_at(bytes, p) == 0xFF) ++p;  // fill bytes
    if (p >= n) return std::nullopt;
    const std::uint8_t marker = byte_at(bytes, p++);
    if (marker == 0xD9) return p;                                        // EOI
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // no length field
    if (p + 2 > n) return std::nullopt;
    const std::size_t length = (std::size_t{byte_at(bytes, p)} << 8) | byte_at(bytes, p + 1);
    if (length < 2 || p + length > n) return std::nullopt;
    p += length;
    if (marker == 0xDA) {
      // Entropy-coded data runs to the next marker that is neither a stuffed 0xFF00 nor a restart.
      while (p + 1 < n) {
        const std::uint8_t next = byte_at(bytes, p + 1);
        if (byte_at(bytes, p) == 0xFF && next != 0x00 && !(next >= 0xD0 && next <= 0xD7)) break;
        ++p;
      }
      if (p + 1 >= n) return std::nullopt;
    }
  }
  return std::nullopt;
}

// Reads big- or little-endian integers of a TIFF structure inside `bytes`, failing on any read
// outside it.
class TiffReader {
 public:
  TiffReader(std::span<const std::byte> bytes, bool little_endian) : bytes_(bytes), little_(little_endian) {}
  std::optional<std::uint32_t> read(std::size_t at, int size) const {
    if (at > bytes_.size() || static_cast<std::size_t>(size) > bytes_.size() - at) return std::nullopt;
    std::uint32_t value = 0;
    for (int i = 0; i < size; ++i) {
      const std::uint32_t b = byte_at(bytes_, at + static_cast<std::size_t>(little_ ? size - 1 - i : i));
      value = (value << 8) | b;
    }
    return value;
  }

 private:
  std::span<const std::byte> bytes_;
  bool little_;
};

// The image offsets of the MP Index IFD (CIPA DC-007, APP2 "MPF\0" in the first image), or nothing
// when the first image has no valid index. Offsets in the index count from the TIFF header inside the
// APP2 segment; the first image's entry is 0 and means the start of the file.
std::optional<std::vector<std::size_t>> mpf_image_offsets(std::span<const std::byte> bytes) {
  const std::size_t n = bytes.size();
  if (n < 4 || byte_at(bytes, 0) != 0xFF || byte_at(bytes, 1) != 0xD8) return std::nullopt;
  std::size_t p = 2;
  while (p + 4 <= n && byte_at(bytes, p) == 0xFF) {
    const std::uint8_t marker = byte_at(bytes, p + 1);
    if (marker == 0xDA || marker == 0xD9) break;  // the index lives in the header segments
    const std::size_t length = (std::size_t{byte_at(bytes, p + 2)} << 8) | byte_at(bytes, p + 3);
    if (length < 2 || p + 2 + length > n) return std::nullopt;
    const std::size_t payload = p + 4, payload_end = p + 2 + length;
    if (marker == 0xE2 && payload + 8 <= payload_end && std::memcmp(&bytes[payload], "MPF", 4) == 0) {
      const std::size_t base = payload + 4;
      const auto tiff = bytes.subspan(base, payload_end - base);
      const bool little = byte_at(tiff, 0) == 'I' && byte_at(tiff, 1) == 'I';
      if (!little && !(byte_at(tiff, 0) == 'M' && byte_at(tiff, 1) == 'M')) return std::nullopt;
      const TiffReader r(tiff, little);
      const auto ifd = r.read(4, 4);
      const auto count = ifd ? r.read(*ifd, 2) : std::nullopt;
      if (!count) return std::nullopt;
      for (std::uint32_t i = 0; i < *count; ++i) {
        const std::size_t entry = *ifd + 2 + 12 * std::size_t{i};
        const auto tag = r.read(entry, 2), size = r.read(entry + 4, 4), where = r.read(entry + 8, 4);
        if (!tag || !size || !where) return std::nullopt;
        if (*tag != 0xB002) continue;  // MP Entry: 16 bytes per image
        std::vector<std::size_t> offsets;
        for (std::uint32_t e = 0; e + 16 <= *size; e += 16) {
          const auto offset = r.read(std::size_t{*where} + e + 8, 4);
          if (!offset) return std::nullopt;
          const std::size_t start = *offset == 0 ? 0 : base + *offset;
          if (start + 2 > n || byte_at(bytes, start) != 0xFF || byte_at(bytes, start + 1) != 0xD8) return std::nullopt;
          offsets.push_back(start);
        }
        // Each image starts after the one before: an index that lists one image twice (or out of
        // order) cannot be trusted, and taking it would make an empty view (found by fuzz_still).
        if (std::adjacent_find(offsets.begin(), offsets.end(), std::greater_equal<>()) != offsets.end())
          return std::nullopt;
        return offsets;
      }
      return std::nullopt;
    }
    p = payload_end;
  }
  return std::nullopt;
}

}  // namespace

std::vector<std::size_t> find_jpeg_images(std::span<const std::byte> bytes) {
  std::vector<std::size_t> starts;
  std::size_t from = 0;
  while (auto soi = next_soi(bytes, from)) {
    starts.push_back(*soi);
    const auto end = end_of_jpeg(bytes, *soi + 2);
    if (!end) break;  // truncated or broken: whatever follows is not a separate image we can trust
    from = *end;
  }
  return starts;
}

std::vector<std::size_t> find_mpo_images(std::span<const std::byte> bytes) {
  auto starts = mpf_image_offsets(bytes).value_or(std::vector<std::size_t>{});
  if (starts.size() < 2) starts = find_jpeg_images(bytes);
  return starts;
}

Image decode_image(std::span<const std::byte> encoded, const std::string& format, const std::string& name,
                   std::int64_t max_pixels) {
  try {
    return to_rgba(image_library::decode(encoded, format, name, {kMaxImageDimension, max_pixels}));
  } catch (const image_library::ImageLibraryError& e) {
    throw StillError(e.what());
  }
}

Image read_image_file(const fs::path& path, std::int64_t max_pixels) {
  require_file(path);
  // OIIO does not know the .jps extension; a JPS file is a JPEG.
  const std::string format = lowercase_extension(path) == ".jps" ? "jpeg" : "";
  try {
    return to_rgba(image_library::read_file(path.string(), format, {kMaxImageDimension, max_pixels}));
  } catch (const image_library::ImageLibraryError& e) {
    throw StillError(e.what());
  }
}

bool is_still_image_name(const std::string& input) {
  static const std::vector<std::string> still = {".png", ".jpg",  ".jpeg", ".jps", ".mpo", ".tif", ".tiff", ".exr",
                                                 ".bmp", ".webp", ".tga",  ".ppm", ".pnm", ".hdr", ".dpx"};
  return std::find(still.begin(), still.end(), lowercase_extension(input)) != still.end();
}

bool is_mpo_name(const std::string& input) { return lowercase_extension(input) == ".mpo"; }

StillStereo load_still(const fs::path& path, const StillOptions& options) {
  if (options.right) {
    if (options.layout && *options.layout != StereoLayout::pair)
      throw StillError(fmt::format("--right gives the right view as a second file; layout {} does not apply",
                                   to_string(*options.layout)));
    return load_pair(path, *options.right, options);
  }
  if (options.layout == StereoLayout::pair)
    throw StillError(
        fmt::format("{}: layout pair needs the right view as a second file (--right FILE)", path.string()));
  if (is_mpo_name(path.string())) {
    require_file(path);
    return load_mpo(path, options);
  }

  Image frame = read_image_file(path, options.max_pixels);
  StillStereo result;
  result.decision =
      detect_stereo_layout({options.layout, std::nullopt, frame.width(), frame.height(), path, options.swap_eyes});
  try {
    result.views = split_frame(frame, result.decision.layout, result.decision.swap_eyes);
  } catch (const LayoutError& e) {
    const std::string hint = result.decision.rule == DetectionRule::flag
                                 ? std::string()
                                 : fmt::format(" (layout chosen by the {} rule; pass --layout to override)",
                                               to_string(result.decision.rule));
    throw StillError(fmt::format("{}: {}{}", path.string(), e.what(), hint));
  }
  return result;
}

}  // namespace nelf
