// PipeWireFrameReader: the frames a PipeWire node sends in shared memory, in each layout a producer
// may use, read as RGBA (BGRx kept in its order). The YUV reference is ffmpeg's own conversion of
// the same raw frame.
#include "inputs/pipewire_frame.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "inputs/view_bytes.hpp"
#include "tests/support/test_support.hpp"

namespace nelf {
namespace {
// This file's own names: its suite is compiled as one unit (tests/CMakeLists.txt).
namespace test_pipewire_frame {

constexpr int kWidth = 64, kHeight = 36;

spa_video_info_raw format_of(spa_video_format f) {
  spa_video_info_raw format{};
  format.format = f;
  format.size = {kWidth, kHeight};
  return format;
}

// A frame's planes, each in memory of its own, and the spa_buffer PipeWire would hand over.
struct Frame {
  std::vector<std::vector<std::uint8_t>> memory;
  std::vector<spa_chunk> chunks;
  std::vector<spa_data> datas;
  spa_buffer buffer{};

  // One spa_data a block of `memory`, the chunk starting `offset` bytes in, rows `stride` apart.
  void add(std::vector<std::uint8_t> bytes, std::uint32_t offset, std::int32_t stride) {
    memory.push_back(std::move(bytes));
    chunks.push_back(spa_chunk{offset, static_cast<std::uint32_t>(memory.back().size()) - offset, stride, 0});
  }
  const spa_buffer& finish() {
    datas.clear();
    for (std::size_t i = 0; i < memory.size(); ++i) {
      spa_data d{};
      d.type = SPA_DATA_MemPtr;
      d.maxsize = static_cast<std::uint32_t>(memory[i].size());
      d.data = memory[i].data();
      d.chunk = &chunks[i];
      datas.push_back(d);
    }
    buffer.n_datas = static_cast<std::uint32_t>(datas.size());
    buffer.datas = datas.data();
    return buffer;
  }
};

// `rows` rows of `row` bytes from `plane` (packed), `stride` apart after `offset` bytes of padding.
std::vector<std::uint8_t> padded(const std::vector<std::uint8_t>& plane, int row, int rows, int stride, int offset) {
  std::vector<std::uint8_t> out(static_cast<std::size_t>(offset + stride * rows), 0xEE);
  for (int y = 0; y < rows; ++y) std::copy_n(plane.begin() + y * row, row, out.begin() + offset + y * stride);
  return out;
}

// Y, U and V of an I420 frame: gradients and a diagonal, so a plane read from the wrong place or
// with the wrong stride shows.
struct I420 {
  std::vector<std::uint8_t> y, u, v;
  I420() {
    for (int r = 0; r < kHeight; ++r)
      for (int c = 0; c < kWidth; ++c) y.push_back(static_cast<std::uint8_t>(16 + (3 * c + 5 * r) % 220));
    for (int r = 0; r < kHeight / 2; ++r)
      for (int c = 0; c < kWidth / 2; ++c) {
        u.push_back(static_cast<std::uint8_t>(40 + 5 * c));
        v.push_back(static_cast<std::uint8_t>(200 - 8 * r));
      }
  }
  std::vector<std::uint8_t> contiguous() const {
    std::vector<std::uint8_t> all = y;
    all.insert(all.end(), u.begin(), u.end());
    all.insert(all.end(), v.begin(), v.end());
    return all;
  }
};

// What ffmpeg makes of `raw` (of FFmpeg pixel format `pix_fmt`) as RGBA.
std::vector<std::uint8_t> ffmpeg_rgba(const std::vector<std::uint8_t>& raw, const std::string& pix_fmt) {
  const test::TempDir dir;
  test::write_file(dir / "in.raw", std::string(raw.begin(), raw.end()));
  const auto r =
      test::run_command("ffmpeg -v error -f rawvideo -pix_fmt " + pix_fmt + " -s 64x36 -i " + test::q(dir / "in.raw") +
                        " -sws_flags bicubic+accurate_rnd+full_chroma_int -f rawvideo -pix_fmt rgba -");
  EXPECT_EQ(r.status, 0) << r.err;
  return std::vector<std::uint8_t>(r.out.begin(), r.out.end());
}

TEST(PipeWireFrameReader, PlanarYuvInAPlaneADataOrAllInOneIsWhatFfmpegMakesOfIt) {
  const I420 frame;
  const auto expected = ffmpeg_rgba(frame.contiguous(), "yuv420p");
  ASSERT_EQ(expected.size(), std::size_t{kWidth * kHeight * 4});
  {
    SCOPED_TRACE("a plane a spa_data, padded rows, chunks not at the start");
    Frame f;
    f.add(padded(frame.y, kWidth, kHeight, 80, 16), 16, 80);
    f.add(padded(frame.u, kWidth / 2, kHeight / 2, 48, 8), 8, 48);
    f.add(padded(frame.v, kWidth / 2, kHeight / 2, 40, 0), 0, 40);
    PipeWireFrameReader reader(format_of(SPA_VIDEO_FORMAT_I420));
    const auto image = reader.read(f.finish());
    ASSERT_TRUE(image);
    EXPECT_EQ(image->pixels, expected);
  }
  {
    SCOPED_TRACE("every plane in one spa_data, rows of 96 bytes");
    std::vector<std::uint8_t> all = padded(frame.y, kWidth, kHeight, 96, 0);
    const auto u = padded(frame.u, kWidth / 2, kHeight / 2, 48, 0), v = padded(frame.v, kWidth / 2, kHeight / 2, 48, 0);
    all.insert(all.end(), u.begin(), u.end());
    all.insert(all.end(), v.begin(), v.end());
    Frame f;
    f.add(all, 0, 96);
    PipeWireFrameReader reader(format_of(SPA_VIDEO_FORMAT_I420));
    const auto image = reader.read(f.finish());
    ASSERT_TRUE(image);
    EXPECT_EQ(image->pixels, expected);
  }
  {
    SCOPED_TRACE("YV12: V before U");
    Frame f;
    f.add(frame.y, 0, kWidth);
    f.add(frame.v, 0, kWidth / 2);
    f.add(frame.u, 0, kWidth / 2);
    PipeWireFrameReader reader(format_of(SPA_VIDEO_FORMAT_YV12));
    const auto image = reader.read(f.finish());
    ASSERT_TRUE(image);
    EXPECT_EQ(image->pixels, expected);
  }
}

TEST(PipeWireFrameReader, SemiPlanarAndPackedYuvAreWhatFfmpegMakesOfThem) {
  const I420 frame;
  std::vector<std::uint8_t> nv12 = frame.y;
  for (std::size_t i = 0; i < frame.u.size(); ++i) nv12.insert(nv12.end(), {frame.u[i], frame.v[i]});
  std::vector<std::uint8_t> yuy2;
  for (int r = 0; r < kHeight; ++r)
    for (int c = 0; c < kWidth; c += 2) {
      const std::size_t chroma = static_cast<std::size_t>((r / 2) * (kWidth / 2) + c / 2);
      const std::size_t luma = static_cast<std::size_t>(r * kWidth + c);
      yuy2.insert(yuy2.end(), {frame.y[luma], frame.u[chroma], frame.y[luma + 1], frame.v[chroma]});
    }
  {
    SCOPED_TRACE("NV12 in one spa_data");
    Frame f;
    f.add(nv12, 0, kWidth);
    PipeWireFrameReader reader(format_of(SPA_VIDEO_FORMAT_NV12));
    const auto image = reader.read(f.finish());
    ASSERT_TRUE(image);
    EXPECT_EQ(image->pixels, ffmpeg_rgba(nv12, "nv12"));
  }
  {
    SCOPED_TRACE("YUY2, rows padded to 160 bytes");
    Frame f;
    f.add(padded(yuy2, kWidth * 2, kHeight, 160, 0), 0, 160);
    PipeWireFrameReader reader(format_of(SPA_VIDEO_FORMAT_YUY2));
    const auto image = reader.read(f.finish());
    ASSERT_TRUE(image);
    EXPECT_EQ(image->pixels, ffmpeg_rgba(yuy2, "yuyv422"));
  }
}

// A one-plane RGB frame of `format` read: `packed`'s rows `stride` bytes apart, the chunk `offset`
// bytes in.
std::optional<CapturedImage> read_rgb(spa_video_format format, const std::vector<std::uint8_t>& packed, int stride,
                                      int offset) {
  Frame f;
  f.add(padded(packed, kWidth * 4, kHeight, stride, offset), static_cast<std::uint32_t>(offset), stride);
  PipeWireFrameReader reader(format_of(format));
  return reader.read(f.finish());
}

TEST(PipeWireFrameReader, RgbOrdersAreCopiedWithTheirStride) {
  std::vector<std::uint8_t> bgrx, xbgr, rgba;
  for (int i = 0; i < kWidth * kHeight; ++i) {
    const auto b = static_cast<std::uint8_t>(i), g = static_cast<std::uint8_t>(i / 7);
    bgrx.insert(bgrx.end(), {b, g, 200, 0});
    xbgr.insert(xbgr.end(), {0, b, g, 200});
    rgba.insert(rgba.end(), {200, g, b, 255});
  }
  // BGRx: kept in its order; what the compositor is given of it is RGBA, alpha 255.
  const auto kept = read_rgb(SPA_VIDEO_FORMAT_BGRx, bgrx, kWidth * 4 + 12, 4);
  ASSERT_TRUE(kept);
  EXPECT_EQ(kept->order, ByteOrder::bgrx);
  EXPECT_EQ(kept->pixels, bgrx);
  EXPECT_EQ(rgba8_block_means(kept->pixels.data(), kWidth * 4, kWidth, kHeight, {1, 1}, kept->order), rgba);
  // xBGR: reordered into RGBA.
  const auto reordered = read_rgb(SPA_VIDEO_FORMAT_xBGR, xbgr, kWidth * 4 + 8, 0);
  ASSERT_TRUE(reordered);
  EXPECT_EQ(reordered->order, ByteOrder::rgba);
  EXPECT_EQ(reordered->pixels, rgba);
}

TEST(PipeWireFrameReader, ABufferShortOfItsFormatOrMarkedCorruptedIsNoFrame) {
  const I420 frame;
  {
    Frame f;
    auto all = frame.contiguous();
    all.resize(all.size() - 1);  // the last V byte missing
    f.add(all, 0, kWidth);
    PipeWireFrameReader reader(format_of(SPA_VIDEO_FORMAT_I420));
    EXPECT_FALSE(reader.read(f.finish()));
  }
  {
    Frame f;
    f.add(frame.y, 0, kWidth);
    f.add(frame.u, 0, kWidth / 2);
    f.add(std::vector<std::uint8_t>(frame.v.begin(), frame.v.end() - 1), 0, kWidth / 2);
    PipeWireFrameReader reader(format_of(SPA_VIDEO_FORMAT_I420));
    EXPECT_FALSE(reader.read(f.finish()));
  }
  {
    Frame f;
    f.add(frame.contiguous(), 0, kWidth);
    f.chunks[0].flags = SPA_CHUNK_FLAG_CORRUPTED;
    PipeWireFrameReader reader(format_of(SPA_VIDEO_FORMAT_I420));
    EXPECT_FALSE(reader.read(f.finish()));
  }
  {
    Frame f;
    f.add(std::vector<std::uint8_t>(kWidth * kHeight * 4 - 1), 0, kWidth * 4);
    PipeWireFrameReader reader(format_of(SPA_VIDEO_FORMAT_RGBA));
    EXPECT_FALSE(reader.read(f.finish()));
  }
  PipeWireFrameReader grey(format_of(SPA_VIDEO_FORMAT_GRAY8));
  EXPECT_FALSE(grey.readable());
  Frame f;
  f.add(frame.y, 0, kWidth);
  EXPECT_FALSE(grey.read(f.finish()));
}

}  // namespace test_pipewire_frame
}  // namespace
}  // namespace nelf
