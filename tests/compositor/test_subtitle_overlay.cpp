// Subtitles drawn into both views: where each eye's copy lands for a parallax, and how it blends.
#include <gtest/gtest.h>

#include <cmath>
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
  std::uint16_t red_sample = 0;
  std::memcpy(&red_sample, sixteen.left.data(), 2);
  EXPECT_EQ(red_sample, 128 * 257 + (0x4040 * 127L + 127) / 255);
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

// A block of opaque white pixels [x0, x1) × [y0, y1), the rest transparent.
SubtitleBitmap block(int width, int height, int x0, int y0, int x1, int y1) {
  SubtitleBitmap s{width, height, std::vector<std::uint8_t>(static_cast<std::size_t>(width) * height * 4, 0), {}};
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) std::memset(&s.rgba[(static_cast<std::size_t>(y) * width + x) * 4], 255, 4);
  return s;
}

// Both views' disparity maps, `width`×`height` map pixels, all at `d`.
StereoDisparity flat_disparity(int width, int height, float d) {
  ViewDisparity map{width, height, std::vector<float>(static_cast<std::size_t>(width) * height, d)};
  return {map, map, DisparityOrigin::known};
}

void set_columns(ViewDisparity& map, int x0, int x1, float d) {
  for (int y = 0; y < map.height; ++y)
    for (int x = x0; x < x1; ++x) map.d[static_cast<std::size_t>(y) * map.width + x] = d;
}

TEST(SubtitleOverlay, TheBoxIsWhatEitherEyesPictureCovers) {
  EXPECT_FALSE(subtitle_box(SubtitleBitmap{}));
  EXPECT_FALSE(subtitle_box(block(40, 20, 0, 0, 0, 0)));  // all transparent
  EXPECT_EQ(subtitle_box(block(40, 20, 5, 12, 30, 18)), (SubtitleBox{5, 12, 30, 18}));
  SubtitleBitmap per_eye = block(40, 20, 10, 12, 20, 18);
  per_eye.right_rgba = block(40, 20, 14, 11, 26, 17).rgba;
  EXPECT_EQ(subtitle_box(per_eye), (SubtitleBox{10, 11, 26, 18}));
}

// The content beneath a line in a 200x100 view whose maps are half as fine (100x50): a plane 3 map
// pixels in front (6 view pixels: 3 % of the width) behind the text, the rest 2 % behind.
TEST(SubtitleOverlay, TheNearestContentBeneathIsInPercentOfTheViewWidth) {
  StereoDisparity d = flat_disparity(100, 50, -2.f);
  set_columns(d.left, 30, 70, 3.f);
  set_columns(d.right, 30, 70, 3.f);
  const SubtitleBox text{70, 80, 130, 95};  // view pixels 70..130: map columns 35..65
  ASSERT_TRUE(content_parallax_beneath(d, text, 200, 100));
  EXPECT_NEAR(*content_parallax_beneath(d, text, 200, 100), 3.0, 1e-6);
  // A line over the far part alone: -2 map pixels, -4 view pixels, 2 % behind.
  EXPECT_NEAR(*content_parallax_beneath(flat_disparity(100, 50, -2.f), text, 200, 100), -2.0, 1e-6);
  // Within reach of the copies (half the largest parallax, 10 view pixels each side) it counts.
  StereoDisparity beside = flat_disparity(100, 50, 0.f);
  set_columns(beside.left, 66, 70, 4.f);  // view columns 132..140
  set_columns(beside.right, 66, 70, 4.f);
  EXPECT_NEAR(*content_parallax_beneath(beside, text, 200, 100), 4.0, 1e-6);
  StereoDisparity far_beside = flat_disparity(100, 50, 0.f);
  set_columns(far_beside.left, 72, 80, 4.f);  // view columns 144..160: out of reach
  set_columns(far_beside.right, 72, 80, 4.f);
  EXPECT_NEAR(*content_parallax_beneath(far_beside, text, 200, 100), 0.0, 1e-6);
}

TEST(SubtitleOverlay, AFewMismatchedPixelsDoNotThrowTheTextForward) {
  StereoDisparity d = flat_disparity(100, 50, 1.f);
  d.left.d[45 * 100 + 50] = 40.f;  // one wild match under the text
  d.right.d[44 * 100 + 52] = 35.f;
  EXPECT_NEAR(*content_parallax_beneath(d, {70, 80, 130, 95}, 200, 100), 1.0, 1e-6);
}

TEST(SubtitleOverlay, NoDepthBeneathWhereTooLittleIsKnown) {
  const float nan = std::nanf("");
  StereoDisparity d = flat_disparity(100, 50, nan);
  EXPECT_FALSE(content_parallax_beneath(d, {70, 80, 130, 95}, 200, 100));
  d.left.d[45 * 100 + 50] = 2.f;  // one pixel of hundreds: too little to say
  EXPECT_FALSE(content_parallax_beneath(d, {70, 80, 130, 95}, 200, 100));
  EXPECT_FALSE(content_parallax_beneath(StereoDisparity{}, {70, 80, 130, 95}, 200, 100));
}

// With the content's depth on the frame, the text's parallax replaces it where the text is (the
// depth-aware compositor then shows the text at its own depth); the maps other frames share are
// left as they were.
TEST(SubtitleOverlay, TheTextsDepthGoesIntoTheFramesDisparity) {
  StereoVideoFrame frame = grey_frame(200, 10, 8);
  const auto shared = std::make_shared<const StereoDisparity>(flat_disparity(100, 5, -1.f));
  frame.disparity = shared;
  draw_subtitles(frame, block(200, 10, 100, 4, 110, 6), 10.0);  // 20 view pixels apart: 10 map pixels
  ASSERT_NE(frame.disparity, shared);
  EXPECT_EQ(shared->left.d, flat_disparity(100, 5, -1.f).left.d);
  const auto at = [](const ViewDisparity& m, int x, int y) { return m.d[static_cast<std::size_t>(y) * m.width + x]; };
  // Left copy at view columns 110..120 (map 55..60), right copy at 90..100 (map 45..50), rows 4..6 (map 2).
  EXPECT_EQ(at(frame.disparity->left, 57, 2), 10.f);
  EXPECT_EQ(at(frame.disparity->left, 50, 2), -1.f);
  EXPECT_EQ(at(frame.disparity->left, 57, 0), -1.f);
  EXPECT_EQ(at(frame.disparity->right, 47, 2), 10.f);
  EXPECT_EQ(at(frame.disparity->right, 57, 2), -1.f);
  EXPECT_EQ(frame.disparity->origin, DisparityOrigin::known);
}

}  // namespace
}  // namespace nelf
