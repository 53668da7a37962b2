#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "inputs/synthetic_source.hpp"

namespace nelf {
namespace {

// Mean x of the pixels whose colour is close to `target` (a sphere's lit colour family), or NaN.
double centroid_x(const Image& img, float r, float g, float b) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const Rgba& p = img.at(x, y);
      const float scale = std::max({p.r, p.g, p.b});
      if (scale < 0.2f) continue;
      if (std::abs(p.r / scale - r) < 0.08f && std::abs(p.g / scale - g) < 0.08f && std::abs(p.b / scale - b) < 0.08f)
        sum += x, ++n;
    }
  return n > 20 ? sum / n : std::nan("");
}

TEST(SyntheticSource, ParsesSpec) {
  const auto s = parse_synthetic_spec("synthetic:duration=2,fps=30,size=320x180");
  EXPECT_DOUBLE_EQ(s.duration_s, 2.0);
  EXPECT_EQ(s.fps, 30);
  EXPECT_EQ(s.eye_width, 320);
  EXPECT_EQ(s.eye_height, 180);
  EXPECT_EQ(SyntheticClip(s).frame_count(), 60);
  EXPECT_EQ(parse_synthetic_spec("synthetic:").fps, 24);
  EXPECT_THROW(parse_synthetic_spec("synthetic:duration=abc"), std::invalid_argument);
  EXPECT_THROW(parse_synthetic_spec("synthetic:size=10"), std::invalid_argument);
  EXPECT_THROW(parse_synthetic_spec("synthetic:colour=red"), std::invalid_argument);
  EXPECT_THROW(parse_synthetic_spec("synthetic:fps=0"), std::invalid_argument);
}

TEST(SyntheticSource, DeterministicAndMoving) {
  SyntheticClipSettings s;
  s.eye_width = 160;
  s.eye_height = 90;
  const SyntheticClip clip(s);
  const auto a = clip.render(0), b = clip.render(0), c = clip.render(12);
  EXPECT_EQ(std::memcmp(a.left.image.data(), b.left.image.data(), 160 * 90 * 16), 0);
  EXPECT_NE(std::memcmp(a.left.image.data(), c.left.image.data(), 160 * 90 * 16), 0);
}

TEST(SyntheticSource, NearObjectsHaveCrossedParallaxFarObjectsUncrossed) {
  SyntheticClipSettings s;
  s.eye_width = 480;
  s.eye_height = 270;
  const auto pair = SyntheticClip(s).render(0);
  EXPECT_NE(std::memcmp(pair.left.image.data(), pair.right.image.data(), 480 * 270 * 16), 0);
  // Orange-red sphere at 0.55 × the screen distance: in front, so the left eye sees it further right.
  const double near_left = centroid_x(pair.left.image, 0.95f / 0.95f, 0.35f / 0.95f, 0.2f / 0.95f);
  const double near_right = centroid_x(pair.right.image, 0.95f / 0.95f, 0.35f / 0.95f, 0.2f / 0.95f);
  ASSERT_FALSE(std::isnan(near_left) || std::isnan(near_right));
  EXPECT_GT(near_left - near_right, 2.0);
  // Violet sphere at 2 × the screen distance: behind, so uncrossed.
  const double far_left = centroid_x(pair.left.image, 0.8f / 0.85f, 0.35f / 0.85f, 0.85f / 0.85f);
  const double far_right = centroid_x(pair.right.image, 0.8f / 0.85f, 0.35f / 0.85f, 0.85f / 0.85f);
  ASSERT_FALSE(std::isnan(far_left) || std::isnan(far_right));
  EXPECT_LT(far_left - far_right, -2.0);
}

TEST(SyntheticSource, ToneIsBoundedAndPeriodic) {
  const SyntheticClip clip{SyntheticClipSettings{}};
  const auto samples = clip.audio(0, 48000);
  float peak = 0;
  for (float v : samples) peak = std::max(peak, std::abs(v));
  EXPECT_GT(peak, 0.25f);
  EXPECT_LE(peak, 0.31f);
  EXPECT_EQ(clip.audio(1000, 10), std::vector<float>(samples.begin() + 1000, samples.begin() + 1010));
}

}  // namespace
}  // namespace nelf
