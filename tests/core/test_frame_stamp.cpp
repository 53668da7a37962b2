// The frame stamp (core/frame_stamp.hpp) reads back what was drawn at any view size, and rejects
// views without one or with a damaged one.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "core/frame_stamp.hpp"

namespace nelf {
namespace {

std::vector<std::uint8_t> stamped_view(const FrameStamp& stamp, int w, int h, int flip_cell = -1) {
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w) * h * 4, 60);
  const auto bits = stamp_bits(stamp);
  for (int i = 0; i < kStampBits; ++i) {
    const StampCell c = stamp_cell(i, w, h);
    const bool white = bits[static_cast<std::size_t>(i)] != (i == flip_cell);
    for (int y = c.y0; y < c.y1; ++y)
      for (int x = c.x0; x < c.x1; ++x)
        for (int k = 0; k < 3; ++k) rgba[(static_cast<std::size_t>(y) * w + x) * 4 + k] = white ? 255 : 0;
  }
  return rgba;
}

TEST(FrameStamp, ReadsBackAtEveryViewSize) {
  const FrameStamp stamp{123456, 987654321012345LL};
  for (auto [w, h] : {std::pair{1280, 720}, {640, 720}, {1280, 360}, {1920, 1080}, {333, 211}}) {
    const auto view = stamped_view(stamp, w, h);
    const auto read = read_frame_stamp(view.data(), w, h, 8);
    ASSERT_TRUE(read) << w << "x" << h;
    EXPECT_EQ(*read, stamp);
  }
}

TEST(FrameStamp, ReadsBackSixteenBitViews) {
  const FrameStamp stamp{7, 42};
  const auto eight = stamped_view(stamp, 640, 360);
  std::vector<std::uint16_t> sixteen(eight.size());
  for (std::size_t i = 0; i < eight.size(); ++i) sixteen[i] = static_cast<std::uint16_t>(eight[i] * 257);
  const auto read = read_frame_stamp(reinterpret_cast<const std::uint8_t*>(sixteen.data()), 640, 360, 16);
  ASSERT_TRUE(read);
  EXPECT_EQ(*read, stamp);
}

TEST(FrameStamp, RejectsAViewWithoutAStampOrWithADamagedOne) {
  const std::vector<std::uint8_t> grey(640 * 360 * 4, 60);
  EXPECT_FALSE(read_frame_stamp(grey.data(), 640, 360, 8));
  const FrameStamp stamp{99, 5000000000LL};
  for (int cell : {0, 10, 50, 127}) {
    const auto damaged = stamped_view(stamp, 640, 360, cell);
    EXPECT_FALSE(read_frame_stamp(damaged.data(), 640, 360, 8)) << "cell " << cell;
  }
  EXPECT_FALSE(read_frame_stamp(grey.data(), 16, 16, 8));  // too small to hold one
}

}  // namespace
}  // namespace nelf
