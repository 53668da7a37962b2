// player/subtitle_depth (--sub-parallax auto): a line just in front of the content beneath it, from
// the frame's own depth or estimated from its views; it comes nearer while read but does not wander
// back, and the next line, or a seek, starts afresh.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>

#include "player/subtitle_depth.hpp"

namespace nelf {
namespace {

constexpr int kWidth = 320, kHeight = 180;

// A frame of grey views whose content is at `d` view pixels of disparity everywhere (known depth,
// maps at the views' resolution), at `pts_s`.
StereoVideoFrame frame_at(float d, double pts_s) {
  StereoVideoFrame f;
  f.width = kWidth;
  f.height = kHeight;
  f.pts_s = pts_s;
  f.left.assign(std::size_t{kWidth} * kHeight * 4, 0x60);
  f.right = f.left;
  ViewDisparity map{kWidth, kHeight, std::vector<float>(std::size_t{kWidth} * kHeight, d)};
  f.disparity = std::make_shared<const StereoDisparity>(StereoDisparity{map, map, DisparityOrigin::known});
  return f;
}

// A line of text: an opaque block low in the view, `x0` to `x0 + 100`.
SubtitleBitmap line(int x0 = 110) {
  SubtitleBitmap s{kWidth, kHeight, std::vector<std::uint8_t>(std::size_t{kWidth} * kHeight * 4, 0), {}};
  for (int y = 150; y < 165; ++y)
    for (int x = x0; x < x0 + 100; ++x) std::memset(&s.rgba[(std::size_t(y) * kWidth + x) * 4], 255, 4);
  return s;
}

const SubtitleDepth kAuto{true, auto_sub_margin_percent};

TEST(SubtitleDepth, AFixedDepthIsTheGivenParallax) {
  SubtitleDepthFollower follower;
  EXPECT_EQ(follower.parallax(frame_at(16.f, 0.0), line(), {false, 1.5}), 1.5);
  EXPECT_EQ(follower.parallax(frame_at(16.f, 0.1), line(), {false, -2.0}), -2.0);
}

TEST(SubtitleDepth, ALineGoesJustInFrontOfTheContentBeneathIt) {
  SubtitleDepthFollower follower;
  // 16 of 320 view pixels: 5 % of the width; the line a quarter percent in front of it.
  EXPECT_NEAR(follower.parallax(frame_at(16.f, 0.0), line(), kAuto), 5.25, 1e-6);
  SubtitleDepthFollower behind;
  EXPECT_NEAR(behind.parallax(frame_at(-8.f, 0.0), line(), kAuto), -2.25, 1e-6);
  // The keys' margin, and never beyond the fusible range.
  SubtitleDepthFollower margin;
  EXPECT_NEAR(margin.parallax(frame_at(16.f, 0.0), line(), {true, 1.0}), 6.0, 1e-6);
  SubtitleDepthFollower close;
  EXPECT_EQ(close.parallax(frame_at(40.f, 0.0), line(), kAuto), max_sub_parallax_percent);
}

TEST(SubtitleDepth, ALineComesNearerWithTheContentButDoesNotWanderBack) {
  SubtitleDepthFollower follower;
  EXPECT_NEAR(follower.parallax(frame_at(8.f, 0.0), line(), kAuto), 2.75, 1e-6);
  EXPECT_NEAR(follower.parallax(frame_at(16.f, 0.1), line(), kAuto), 5.25, 1e-6);  // nearer: follows
  EXPECT_NEAR(follower.parallax(frame_at(0.f, 0.2), line(), kAuto), 5.25, 1e-6);   // farther: stays
  // The next line (another place on screen) starts from what is beneath it now.
  EXPECT_NEAR(follower.parallax(frame_at(0.f, 0.3), line(60), kAuto), 0.25, 1e-6);
  // A gap without a line, then the same words again: a new line too.
  follower.parallax(frame_at(0.f, 0.4), SubtitleBitmap{}, kAuto);
  EXPECT_NEAR(follower.parallax(frame_at(-4.f, 0.5), line(60), kAuto), -1.0, 1e-6);
}

TEST(SubtitleDepth, ASeekStartsTheLineAfresh) {
  SubtitleDepthFollower follower;
  EXPECT_NEAR(follower.parallax(frame_at(16.f, 5.0), line(), kAuto), 5.25, 1e-6);
  EXPECT_NEAR(follower.parallax(frame_at(0.f, 2.0), line(), kAuto), 0.25, 1e-6);  // back
  EXPECT_NEAR(follower.parallax(frame_at(16.f, 2.1), line(), kAuto), 5.25, 1e-6);
  EXPECT_NEAR(follower.parallax(frame_at(0.f, 9.0), line(), kAuto), 0.25, 1e-6);  // forward
}

TEST(SubtitleDepth, UnknownContentKeepsTheLastLinesDepth) {
  SubtitleDepthFollower follower;
  EXPECT_NEAR(follower.parallax(frame_at(16.f, 0.0), line(), kAuto), 5.25, 1e-6);
  EXPECT_NEAR(follower.parallax(frame_at(std::nanf(""), 0.1), line(60), kAuto), 5.25, 1e-6);
  // A flat grey frame without depth: nothing to estimate from.
  StereoVideoFrame flat = frame_at(0.f, 0.2);
  flat.disparity.reset();
  EXPECT_NEAR(follower.parallax(flat, line(), kAuto), 5.25, 1e-6);
}

// Smooth value noise: the texture of a surface the matcher can find.
std::uint8_t texture(int u, int v) {
  const auto lattice = [](int i, int j) {
    std::uint32_t h = static_cast<std::uint32_t>(i) * 73856093u ^ static_cast<std::uint32_t>(j) * 19349663u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return static_cast<float>(h & 0xffu);
  };
  const int i = static_cast<int>(std::floor(u / 4.0)), j = static_cast<int>(std::floor(v / 4.0));
  const float fx = static_cast<float>(u - 4 * i) / 4.f, fy = static_cast<float>(v - 4 * j) / 4.f;
  const float top = lattice(i, j) * (1 - fx) + lattice(i + 1, j) * fx;
  const float bottom = lattice(i, j + 1) * (1 - fx) + lattice(i + 1, j + 1) * fx;
  return static_cast<std::uint8_t>(top * (1 - fy) + bottom * fy);
}

// Without depth on the frame, it is estimated from the views: a textured surface 15 view pixels in
// front (4.69 % of the width) puts the line at 4.94 %.
TEST(SubtitleDepth, WithoutTheFramesDepthItIsEstimatedFromTheViews) {
  StereoVideoFrame f = frame_at(0.f, 0.0);
  f.disparity.reset();
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const std::size_t i = (std::size_t(y) * kWidth + x) * 4;
      std::memset(&f.left[i], texture(x, y), 3);
      std::memset(&f.right[i], texture(x + 15, y), 3);  // the point of left x at x - 15: in front
    }
  SubtitleDepthFollower follower;
  EXPECT_NEAR(follower.parallax(f, line(), kAuto), 100.0 * 15 / kWidth + 0.25, 0.2);
}

}  // namespace
}  // namespace nelf
