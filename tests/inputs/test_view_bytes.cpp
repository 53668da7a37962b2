#include "inputs/view_bytes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace {

// A pattern no block of which is uniform, so that every mean rounds something.
std::vector<std::uint8_t> pattern(int width, int height) {
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(width) * height * 4);
  for (std::size_t i = 0; i < rgba.size(); ++i) rgba[i] = static_cast<std::uint8_t>((i * 7919u + i / 13) >> 2);
  return rgba;
}

// Checks every block's mean of rows stored top-down (stride > 0) or bottom-up (stride < 0).
void expect_block_means(int width, int height, std::array<int, 2> block, bool bottom_up,
                        nelf::ByteOrder order = nelf::ByteOrder::rgba) {
  const std::vector<std::uint8_t> rgba = pattern(width, height);
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(width) * 4;
  // The view's row y: stored at row y (top-down) or height - 1 - y (bottom-up).
  const auto at = [&](int x, int y, int c) {
    const int stored = bottom_up ? height - 1 - y : y;
    if (order == nelf::ByteOrder::bgrx && c != 3) c = 2 - c;  // R is stored third, B first
    return rgba[static_cast<std::size_t>(stored) * width * 4 + static_cast<std::size_t>(x) * 4 + c];
  };
  const std::uint8_t* top = bottom_up ? rgba.data() + (height - 1) * stride : rgba.data();
  const std::vector<std::uint8_t> out =
      nelf::rgba8_block_means(top, bottom_up ? -stride : stride, width, height, block, order);
  const int w = width / block[0], h = height / block[1];
  ASSERT_EQ(out.size(), static_cast<std::size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        double sum = 0;
        for (int j = 0; j < block[1]; ++j)
          for (int i = 0; i < block[0]; ++i) sum += at(x * block[0] + i, y * block[1] + j, c);
        const double mean = sum / (block[0] * block[1]);
        ASSERT_LE(std::abs(out[(static_cast<std::size_t>(y) * w + x) * 4 + c] - mean), 0.5)
            << "block " << x << "," << y << " channel " << c;
      }
      ASSERT_EQ(out[(static_cast<std::size_t>(y) * w + x) * 4 + 3], 255);
    }
}

}  // namespace

TEST(ViewBytes, BlockMeansAreEachBlocksMeanRoundedWithTheViewsTopRowFirst) {
  for (const bool bottom_up : {false, true}) {
    SCOPED_TRACE(bottom_up ? "bottom-up" : "top-down");
    expect_block_means(64, 36, {2, 2}, bottom_up);
    expect_block_means(64, 36, {2, 1}, bottom_up);
    expect_block_means(66, 37, {3, 2}, bottom_up);  // the rows and columns left over are left out
    expect_block_means(40, 30, {4, 4}, bottom_up);
  }
}

TEST(ViewBytes, BlockMeansOfBgrxRowsComeOutRgba) {
  for (const bool bottom_up : {false, true}) {
    SCOPED_TRACE(bottom_up ? "bottom-up" : "top-down");
    expect_block_means(64, 36, {2, 2}, bottom_up, nelf::ByteOrder::bgrx);
    expect_block_means(66, 37, {3, 2}, bottom_up, nelf::ByteOrder::bgrx);
  }
}

TEST(ViewBytes, AOneByOneBlockCopiesTheRows) {
  const int width = 8, height = 5;
  const std::vector<std::uint8_t> rgba = pattern(width, height);
  const std::ptrdiff_t stride = width * 4;
  const std::vector<std::uint8_t> same = nelf::rgba8_block_means(rgba.data(), stride, width, height, {1, 1});
  EXPECT_EQ(same, rgba);
  const std::vector<std::uint8_t> flipped =
      nelf::rgba8_block_means(rgba.data() + (height - 1) * stride, -stride, width, height, {1, 1});
  for (int y = 0; y < height; ++y)
    EXPECT_TRUE(std::equal(flipped.begin() + y * stride, flipped.begin() + (y + 1) * stride,
                           rgba.begin() + (height - 1 - y) * stride));
}

TEST(ViewBytes, AOneByOneBlockOfBgrxRowsSwapsRedAndBlueWithAlpha255) {
  const int width = 8, height = 5;
  const std::vector<std::uint8_t> bgrx = pattern(width, height);
  const std::ptrdiff_t stride = width * 4;
  for (const bool bottom_up : {false, true}) {
    SCOPED_TRACE(bottom_up ? "bottom-up" : "top-down");
    const std::uint8_t* top = bottom_up ? bgrx.data() + (height - 1) * stride : bgrx.data();
    const std::vector<std::uint8_t> rgba =
        nelf::rgba8_block_means(top, bottom_up ? -stride : stride, width, height, {1, 1}, nelf::ByteOrder::bgrx);
    ASSERT_EQ(rgba.size(), bgrx.size());
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const std::uint8_t* in = &bgrx[static_cast<std::size_t>(bottom_up ? height - 1 - y : y) * stride + x * 4];
        const std::uint8_t* out = &rgba[static_cast<std::size_t>(y) * stride + x * 4];
        EXPECT_EQ(out[0], in[2]);
        EXPECT_EQ(out[1], in[1]);
        EXPECT_EQ(out[2], in[0]);
        EXPECT_EQ(out[3], 255);
      }
  }
}
