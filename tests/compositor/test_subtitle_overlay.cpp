// Subtitles drawn into both views: where each eye's copy lands for a parallax, and how it blends.
#include <gtest/gtest.h>

#include <cstring>

#include "compositor/overlays/subtitle_overlay.hpp"

namespace nelf {
namespace {

StereoVideoFrame grey_frame(int width, int height, int bits) {
  StereoVideoFrame frame;
  frame.width = width;
  frame.height = height;
  frame.bits = bits;
  frame.left.assign(static_cast<std::size_t>(width) * height * bytes_per_pixel(bits), 0x40);
  frame.right = frame.left;
  return frame;
}

// One opaque white pixel at (x, y), the rest transparent.
SubtitleBitmap dot(int width, int height, int x, int y) {
  SubtitleBitmap s{width, height, std::vector<std::uint8_t>(static_cast<std::size_t>(width) * height * 4, 0), {}};
  std::memset(&s.rgba[(static_cast<std::size_t>(y) * width + x) * 4], 255, 4);
  return s;
}

// The columns of row `y` of an 8-bit view whose red is white.
std::vector<int> white_columns(const std::vector<std::uint8_t>& view, int width, int y) {
  std::vector<int> columns;
  for (int x = 0; x < width; ++x)
    if (view[(static_cast<std::size_t>(y) * width + x) * 4] == 255) columns.push_back(x);
  return columns;
}

TEST(SubtitleOverlay, PositiveParallaxPutsTheLeftCopyRightOfTheRightOne) {
  StereoVideoFrame frame = grey_frame(200, 10, 8);
  draw_subtitles(frame, dot(200, 10, 100, 5), 10.0);  // 10 % of 200 px: 20 px apart
  EXPECT_EQ(white_columns(frame.left, 200, 5), std::vector<int>{110});
  EXPECT_EQ(white_columns(frame.right, 200, 5), std::vector<int>{90});
}

TEST(SubtitleOverlay, NegativeParallaxPutsItBehindTheScreen) {
  StereoVideoFrame frame = grey_frame(200, 10, 8);
  draw_subtitles(frame, dot(200, 10, 100, 5), -5.0);
  EXPECT_EQ(white_columns(frame.left, 200, 5), std::vector<int>{95});
  EXPECT_EQ(white_columns(frame.right, 200, 5), std::vector<int>{105});
}

TEST(SubtitleOverlay, ZeroParallaxIsTheSamePlaceInBothEyes) {
  StereoVideoFrame frame = grey_frame(200, 10, 8);
  draw_subtitles(frame, dot(200, 10, 37, 2), 0.0);
  EXPECT_EQ(white_columns(frame.left, 200, 2), std::vector<int>{37});
  EXPECT_EQ(white_columns(frame.right, 200, 2), std::vector<int>{37});
  EXPECT_EQ(frame.left, frame.right);
}

TEST(SubtitleOverlay, ShiftedOutOfTheViewIsCutOff) {
  StereoVideoFrame frame = grey_frame(100, 4, 8);
  draw_subtitles(frame, dot(100, 4, 98, 1), 10.0);  // the left copy would land at 103
  EXPECT_TRUE(white_columns(frame.left, 100, 1).empty());
  EXPECT_EQ(white_columns(frame.right, 100, 1), std::vector<int>{93});
}

TEST(SubtitleOverlay, BlendsPremultipliedOverEightAndSixteenBits) {
  SubtitleBitmap half{1, 1, {128, 0, 0, 128}, {}};  // red at half opacity, premultiplied
  StereoVideoFrame eight = grey_frame(1, 1, 8);
  draw_subtitles(eight, half, 0.0);
  EXPECT_EQ(eight.left[0], 128 + (0x40 * 127 + 127) / 255);
  EXPECT_EQ(eight.left[1], (0x40 * 127 + 127) / 255);
  EXPECT_EQ(eight.left[3], 255);
  StereoVideoFrame sixteen = grey_frame(1, 1, 16);
  draw_subtitles(sixteen, half, 0.0);
  std::uint16_t red = 0;
  std::memcpy(&red, sixteen.left.data(), 2);
  EXPECT_EQ(red, 128 * 257 + (0x4040 * 127L + 127) / 255);
}

TEST(SubtitleOverlay, BlockMeansTakeASubtitleOfTheirOwnSize) {
  StereoVideoFrame frame = grey_frame(50, 20, 8);  // the bytes of 50x20 means
  frame.width = 100;
  frame.height = 80;
  frame.block = {2, 4};
  EXPECT_EQ(subtitle_canvas(frame), (std::array<int, 2>{50, 20}));
  draw_subtitles(frame, dot(50, 20, 25, 10), 4.0);  // 4 % of 50: 2 apart
  EXPECT_EQ(white_columns(frame.left, 50, 10), std::vector<int>{26});
  EXPECT_EQ(white_columns(frame.right, 50, 10), std::vector<int>{24});
  EXPECT_THROW(draw_subtitles(frame, dot(100, 80, 0, 0), 0.0), std::invalid_argument);
}

TEST(SubtitleOverlay, SubtitlesAuthoredPerEyeGiveEachEyeItsOwnShiftedTheSame) {
  StereoVideoFrame frame = grey_frame(200, 10, 8);
  SubtitleBitmap eyes = dot(200, 10, 50, 5);
  eyes.right_rgba = dot(200, 10, 150, 5).rgba;
  draw_subtitles(frame, eyes, 5.0);  // 5 % of 200 px: 10 px apart
  EXPECT_EQ(white_columns(frame.left, 200, 5), std::vector<int>{55});
  EXPECT_EQ(white_columns(frame.right, 200, 5), std::vector<int>{145});
  eyes.right_rgba.resize(4);
  EXPECT_THROW(draw_subtitles(frame, eyes, 0.0), std::invalid_argument);
}

TEST(SubtitleOverlay, AnEmptySubtitleDrawsNothing) {
  StereoVideoFrame frame = grey_frame(10, 10, 8);
  const StereoVideoFrame before = frame;
  draw_subtitles(frame, SubtitleBitmap{10, 10, {}, {}}, 3.0);
  EXPECT_EQ(frame.left, before.left);
  EXPECT_EQ(frame.right, before.right);
}

}  // namespace
}  // namespace nelf
