#pragma once
// Test media written at test time (DESIGN.md §9: no committed blobs): images via OpenImageIO,
// hand-made PNG headers, MPO files assembled from JPEGs.
#include <OpenImageIO/imageio.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "support/test_support.hpp"

namespace nelf::test {

// Writes the first `channels` channels of `image` (1 = its red channel as gray) as `type`.
inline void write_test_image(const std::filesystem::path& path, const Image& image, int channels,
                             OIIO::TypeDesc type = OIIO::TypeDesc::UINT8, const char* format = nullptr) {
  auto out = OIIO::ImageOutput::create(format ? std::string(format) : path.string());
  if (!out) throw std::runtime_error("no OIIO writer for " + path.string() + ": " + OIIO::geterror());
  OIIO::ImageSpec spec(image.width(), image.height(), channels, type);
  if (!out->open(path.string(), spec)) throw std::runtime_error(out->geterror());
  const auto stride = static_cast<OIIO::stride_t>(sizeof(Rgba));
  if (!out->write_image(OIIO::TypeDesc::FLOAT, image.data(), stride, stride * image.width()) || !out->close())
    throw std::runtime_error(out->geterror());
}

inline Image filled_image(int w, int h, Rgba colour) {
  Image image(w, h);
  for (Rgba& px : image.pixels()) px = colour;
  return image;
}

// Reads an image file back as float RGBA (test side, independent of nelf's reader).
struct ReadBack {
  int width = 0, height = 0, channels = 0;
  int bits = 0;  // per channel, as stored in the file
  std::vector<float> pixels;
  float at(int x, int y, int c) const {
    return pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) *
                      static_cast<std::size_t>(channels) +
                  static_cast<std::size_t>(c)];
  }
};
inline ReadBack read_back(const std::filesystem::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) throw std::runtime_error("cannot read back " + path.string() + ": " + OIIO::geterror());
  ReadBack r{
      in->spec().width, in->spec().height, in->spec().nchannels, static_cast<int>(in->spec().format.size() * 8), {}};
  r.pixels.resize(static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height) *
                  static_cast<std::size_t>(r.channels));
  if (!in->read_image(0, 0, 0, r.channels, OIIO::TypeDesc::FLOAT, r.pixels.data()))
    throw std::runtime_error(in->geterror());
  return r;
}

inline std::uint32_t crc32(const std::string& bytes) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (unsigned char c : bytes) {
    crc ^= c;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

inline std::string be32(std::uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8), static_cast<char>(v)};
}

// A PNG signature and a valid IHDR chunk (8-bit RGB) claiming `width` x `height`, with no pixel data:
// a header that lies about the size, as a hostile or corrupt file would.
inline std::string png_header_claiming(std::uint32_t width, std::uint32_t height) {
  std::string ihdr = "IHDR" + be32(width) + be32(height) + std::string("\x08\x02\x00\x00\x00", 5);
  // An empty IDAT ends the header part that readers parse before they report the size; IEND closes.
  return std::string("\x89PNG\r\n\x1a\n", 8) + be32(13) + ihdr + be32(crc32(ihdr)) + be32(0) + "IDAT" +
         be32(crc32("IDAT")) + be32(0) + "IEND" + be32(crc32("IEND"));
}

// A JPEG with an APP1 segment holding a complete small JPEG (as an EXIF thumbnail does) inserted
// after its SOI, so that a naive scan for SOI/EOI markers would split the file in the wrong place.
inline std::string with_embedded_thumbnail(const std::string& jpeg, const std::string& thumbnail) {
  const std::string payload = std::string("Exif\0\0", 6) + thumbnail;
  const std::size_t length = payload.size() + 2;
  if (length > 0xFFFF) throw std::runtime_error("thumbnail too large for an APP1 segment");
  std::string segment = std::string("\xFF\xE1", 2) + static_cast<char>(length >> 8) + static_cast<char>(length & 0xFF);
  return jpeg.substr(0, 2) + segment + payload + jpeg.substr(2);
}

inline std::string le16(std::uint32_t v) { return {static_cast<char>(v), static_cast<char>(v >> 8)}; }
inline std::string le32(std::uint32_t v) { return le16(v & 0xFFFF) + le16(v >> 16); }

// A minimal MPO in the CIPA DC-007 layout: the left JPEG with an APP2 "MPF" segment (little-endian
// MP Index IFD: version and two MP entries) right after its SOI, then `gap` bytes, then the right JPEG.
inline std::string mpo_with_index(const std::string& left, const std::string& gap, const std::string& right) {
  constexpr std::uint32_t kIfd = 8, kEntries = kIfd + 2 + 2 * 12 + 4;  // MP entries follow the IFD
  constexpr std::size_t kTiffSize = kEntries + 2 * 16;
  constexpr std::size_t kSegmentSize = 2 + 2 + 4 + kTiffSize;
  constexpr std::size_t kBase = 2 + 2 + 2 + 4;  // SOI, APP2 marker, length, "MPF\0": the TIFF header
  const std::size_t left_size = left.size() + kSegmentSize;
  const std::uint32_t right_offset = static_cast<std::uint32_t>(left_size + gap.size() - kBase);
  std::string tiff = "II*" + std::string(1, '\0') + le32(kIfd) + le16(2);
  tiff += le16(0xB000) + le16(7) + le32(4) + "0100";                                           // MP format version
  tiff += le16(0xB002) + le16(7) + le32(32) + le32(kEntries);                                  // MP entries
  tiff += le32(0);                                                                             // no next IFD
  tiff += le32(0x20030000) + le32(static_cast<std::uint32_t>(left_size)) + le32(0) + le32(0);  // base image
  tiff += le32(0x00020002) + le32(static_cast<std::uint32_t>(right.size())) + le32(right_offset) + le32(0);
  const std::size_t length = kSegmentSize - 2;
  const std::string segment = std::string("\xFF\xE2", 2) + static_cast<char>(length >> 8) +
                              static_cast<char>(length & 0xFF) + std::string("MPF\0", 4) + tiff;
  return left.substr(0, 2) + segment + left.substr(2) + gap + right;
}

// A JPS (right view first) and an MPO (two JPEGs), written for the test.
inline void write_stereo_photos(const TempDir& dir) {
  const Image red = filled_image(32, 18, {0.75f, 0.2f, 0.1f, 1.f}),
              blue = filled_image(32, 18, {0.1f, 0.25f, 0.75f, 1.f});
  Image jps(64, 18);
  for (int y = 0; y < 18; ++y)
    for (int x = 0; x < 32; ++x) {
      jps.at(x, y) = blue.at(x, y);
      jps.at(32 + x, y) = red.at(x, y);
    }
  write_test_image(dir / "photo.jps", jps, 3, OIIO::TypeDesc::UINT8, "jpeg");
  write_test_image(dir / "l.jpg", red, 3, OIIO::TypeDesc::UINT8, "jpeg");
  write_test_image(dir / "r.jpg", blue, 3, OIIO::TypeDesc::UINT8, "jpeg");
  write_file(dir / "camera.mpo", read_file(dir / "l.jpg") + read_file(dir / "r.jpg"));
}

}  // namespace nelf::test
