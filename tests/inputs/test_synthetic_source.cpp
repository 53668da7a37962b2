#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

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

TEST(SyntheticSource, ParsesThePlanesSceneAndTheCamera) {
  const auto s = parse_synthetic_spec("synthetic:scene=planes,near=400,far=1500");
  EXPECT_EQ(s.scene, SyntheticScene::planes);
  EXPECT_DOUBLE_EQ(s.near_mm, 400.0);
  EXPECT_DOUBLE_EQ(s.far_mm, 1500.0);
  EXPECT_FALSE(s.camera_given);
  const auto camera = parse_synthetic_spec("synthetic:screen=800,ipd=60,fov=30");
  EXPECT_TRUE(camera.camera_given);
  EXPECT_DOUBLE_EQ(camera.screen_distance_mm, 800.0);
  EXPECT_DOUBLE_EQ(camera.ipd_mm, 60.0);
  EXPECT_DOUBLE_EQ(camera.horizontal_fov_deg, 30.0);
  EXPECT_THROW(parse_synthetic_spec("synthetic:scene=cubes"), std::invalid_argument);
  EXPECT_THROW(parse_synthetic_spec("synthetic:scene=planes,near=1200"), std::invalid_argument);  // behind far
  EXPECT_THROW(parse_synthetic_spec("synthetic:fov=0"), std::invalid_argument);
  EXPECT_THROW(parse_synthetic_spec("synthetic:ipd=-3"), std::invalid_argument);
}

TEST(SyntheticSource, ThePlanesKnowTheirDisparityAndRegions) {
  SyntheticClipSettings s;
  s.scene = SyntheticScene::planes;
  s.eye_width = 240;
  s.eye_height = 135;
  const SyntheticClip clip(s);
  const auto disparity = clip.disparity(0);
  ASSERT_TRUE(disparity);
  EXPECT_EQ(disparity->origin, DisparityOrigin::known);
  const auto regions = clip.regions(0);
  ASSERT_EQ(regions.size(), 2u);
  EXPECT_EQ(regions[0].name, "near");
  EXPECT_EQ(regions[1].name, "far");
  // δ = e (D/Z − 1) on the screen, in view pixels: 250 mm is 3 e in front, 1000 mm (the screen) 0.
  const double screen_w = 2 * s.screen_distance_mm * std::tan(s.horizontal_fov_deg * std::numbers::pi / 360.0);
  const double near_px = s.ipd_mm * 3 * s.eye_width / screen_w;
  std::size_t near_count = 0;
  for (std::size_t k = 0; k < disparity->left.d.size(); ++k) {
    const bool near = regions[0].left_mask[k] != 0;
    EXPECT_NE(near, regions[1].left_mask[k] != 0);  // every pixel shows exactly one plane
    EXPECT_NEAR(disparity->left.d[k], near ? near_px : 0.0, 1e-3);
    near_count += near;
  }
  // The near plane covers a third of the view's width and half its height.
  EXPECT_NEAR(static_cast<double>(near_count) / disparity->left.d.size(), 1.0 / 6, 0.01);
  // The same near pixel is d further left in the right view: x_R = x_L − d.
  const auto pair = clip.render(0);
  // (between two pixels: linearly interpolated; the texture's cells are three pixels wide)
  const int shift = static_cast<int>(std::floor(near_px));
  const float frac = static_cast<float>(near_px - shift);
  const int row = s.eye_height / 2;
  int matched = 0, tried = 0;
  for (int x = shift + 1; x < s.eye_width; ++x) {
    if (!regions[0].left_mask[static_cast<std::size_t>(row) * s.eye_width + x]) continue;
    ++tried;
    const Rgba& l = pair.left.image.at(x, row);
    const Rgba& a = pair.right.image.at(x - shift, row);
    const Rgba& b = pair.right.image.at(x - shift - 1, row);
    const auto mix = [&](float p, float q) { return p + (q - p) * frac; };
    matched += std::abs(l.r - mix(a.r, b.r)) + std::abs(l.g - mix(a.g, b.g)) + std::abs(l.b - mix(a.b, b.b)) < 0.05f;
  }
  ASSERT_GT(tried, 20);
  EXPECT_GT(matched, tried * 9 / 10);
  EXPECT_THROW(clip.disparity(clip.frame_count()), std::out_of_range);
}

TEST(SyntheticSource, TheSpheresKnowTheirDisparityToo) {
  SyntheticClipSettings s;
  s.eye_width = 160;
  s.eye_height = 90;
  const SyntheticClip clip(s);
  const auto disparity = clip.disparity(0);
  EXPECT_TRUE(clip.regions(0).empty());
  // The wall at 3 D is behind the screen everywhere it shows (δ = e (1/3 − 1)), spheres in front or behind.
  const double screen_w = 2 * s.screen_distance_mm * std::tan(s.horizontal_fov_deg * std::numbers::pi / 360.0);
  const float wall = static_cast<float>(s.ipd_mm * (1.0 / 3 - 1) * s.eye_width / screen_w);
  int wall_count = 0, in_front = 0;
  for (float d : disparity->right.d) {
    wall_count += std::abs(d - wall) < 1e-3f;
    in_front += d > 0.1f;
  }
  EXPECT_GT(wall_count, 160 * 90 / 2);
  EXPECT_GT(in_front, 20);
}

TEST(SyntheticSource, FilmedForALensArrayDisplay) {
  // The camera takes the emulated screen's distance, width and IPD; a given camera stays as it is.
  Profile display = load_profile("hmz-t1");
  const auto matched = matched_to_display(parse_synthetic_spec("synthetic:scene=planes"), display);
  EXPECT_DOUBLE_EQ(matched.screen_distance_mm, 1000.0);  // the profile's virtual image
  EXPECT_DOUBLE_EQ(matched.ipd_mm, display.viewing.ipd_mm);
  EXPECT_GT(matched.horizontal_fov_deg, 1.0);
  EXPECT_LT(matched.horizontal_fov_deg, 90.0);
  const auto given = matched_to_display(parse_synthetic_spec("synthetic:fov=40"), display);
  EXPECT_DOUBLE_EQ(given.horizontal_fov_deg, 40.0);
  const auto stock = matched_to_display(parse_synthetic_spec("synthetic:"), load_profile("hmz-t1-stock"));
  EXPECT_DOUBLE_EQ(stock.horizontal_fov_deg, 40.0);
}

}  // namespace
}  // namespace nelf
