// optics/depth: disparity ↔ distance through the emulated screen's geometry, and the search for
// where a ray meets the content's surface.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "optics/depth.hpp"

namespace nelf {
namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

DepthGeometry geometry() { return {1000.0, {500.0, 281.25}, 63.0}; }

TEST(DepthGeometry, DisparityIsZeroOnTheScreenAndMinusTheIpdAtInfinity) {
  const DepthGeometry g = geometry();
  EXPECT_DOUBLE_EQ(disparity_mm_from_depth(g, 1000.0), 0.0);
  EXPECT_DOUBLE_EQ(disparity_mm_from_depth(g, 250.0), 189.0);  // 63 · (4 − 1)
  EXPECT_NEAR(disparity_mm_from_depth(g, 1e12), -63.0, 1e-6);
  EXPECT_TRUE(std::isinf(depth_mm_from_disparity(g, -63.0)));
  EXPECT_TRUE(std::isinf(depth_mm_from_disparity(g, -80.0)));
  for (double z : {200.0, 250.0, 500.0, 1000.0, 4000.0})
    EXPECT_NEAR(depth_mm_from_disparity(g, disparity_mm_from_depth(g, z)), z, 1e-9 * z);
}

TEST(DepthGeometry, DistanceFromTheProfilesScreen) {
  const Profile profile = load_profile("hmz-t1");
  const EyeMapping m = make_eye_mapping(profile, Eye::left, 16.0 / 9.0);
  const DepthGeometry g = depth_geometry(profile, m);
  EXPECT_DOUBLE_EQ(g.screen_distance_mm, m.render_distance_mm);
  EXPECT_DOUBLE_EQ(g.ipd_mm, profile.viewing.ipd_mm);
  EXPECT_DOUBLE_EQ(g.screen_size_mm.x, m.screen_size_mm.x);
}

// The other eye's pupil (p = e) sees the left view shifted by the whole disparity; a pupil point
// above the centre sees the content move down in t (t grows downwards) by the screen's aspect.
TEST(DepthGeometry, PupilGainMakesTheOtherEyeTheOtherView) {
  const DepthGeometry g = geometry();
  const Vec2 other_eye = pupil_gain(g, {63.0, 0.0});
  EXPECT_DOUBLE_EQ(other_eye.x, 1.0);
  EXPECT_DOUBLE_EQ(other_eye.y, 0.0);
  const Vec2 up = pupil_gain(g, {0.0, 63.0});
  EXPECT_DOUBLE_EQ(up.x, 0.0);
  EXPECT_NEAR(up.y, -500.0 / 281.25, 1e-12);
}

TEST(DisparitySurface, UnknownTexelsBetweenTwoDepthsTakeTheFartherOne) {
  // An occlusion beside a near surface (disparity 12) on a far one (-4): the band is the far
  // surface, whichever side is nearer; at the ends of the row the one known value.
  const float unknown = std::numeric_limits<float>::quiet_NaN();
  const DisparitySurface s(ViewDisparity{8, 1, {unknown, -4.f, unknown, unknown, unknown, 12.f, unknown, unknown}});
  const float expected[] = {-4, -4, -4, -4, -4, 12, 12, 12};
  for (int x = 0; x < 8; ++x) EXPECT_FLOAT_EQ(s.values()[x] * 8, expected[x]) << x;
}

TEST(DisparitySurface, ValuesAreFractionsOfTheWidthAndUnknownTexelsTakeAKnownOne) {
  ViewDisparity d{4, 2, {nan, 8.f, nan, nan, nan, nan, nan, nan}};
  const DisparitySurface s(d);
  EXPECT_FALSE(s.unknown());
  ASSERT_EQ(s.values().size(), 8u);
  for (int x = 0; x < 4; ++x) EXPECT_FLOAT_EQ(s.values()[x], 2.f) << x;  // 8 px of a 4 px wide map
  for (int x = 4; x < 8; ++x) EXPECT_FLOAT_EQ(s.values()[x], 0.f) << "a row with nothing known is the screen";
  EXPECT_FLOAT_EQ(s.front(), 2.f);
  EXPECT_FLOAT_EQ(s.back(), 0.f);
  EXPECT_TRUE(DisparitySurface(ViewDisparity{2, 1, {nan, nan}}).unknown());
}

TEST(DisparitySurface, RefusesAMapThatDoesNotHoldTogether) {
  EXPECT_THROW(DisparitySurface(ViewDisparity{3, 2, {0.f, 0.f}}), std::invalid_argument);
  EXPECT_THROW(DisparitySurface(ViewDisparity{0, 0, {}}), std::invalid_argument);
}

TEST(DisparitySurface, AFlatOrConstantSurfaceIsHitWithoutSearching) {
  const DisparitySurface flat(ViewDisparity{8, 8, std::vector<float>(64, 0.f)});
  const Vec2 h = flat.hit({0.3, 0.7}, {0.05, -0.02});
  EXPECT_EQ(h.x, 0.3);
  EXPECT_EQ(h.y, 0.7);
  const DisparitySurface plane(ViewDisparity{8, 8, std::vector<float>(64, 2.f)});  // 0.25 of the width
  const Vec2 p = plane.hit({0.3, 0.7}, {0.1, 0.0});
  EXPECT_DOUBLE_EQ(p.x, 0.3 + 0.1 * 0.25);
  EXPECT_EQ(p.y, 0.7);
}

// Left half near (δ/W = 0.4), right half far (0): a ray meeting the flat screen just right of the
// edge, from a pupil point on the left (negative gain), meets the near half first; one meeting it
// far to the right meets the far plane where it is.
TEST(DisparitySurface, TheFrontMostCrossingWins) {
  ViewDisparity d{100, 1, std::vector<float>(100, 0.f)};
  for (int x = 0; x < 50; ++x) d.d[x] = 40.f;
  const DisparitySurface s(d);
  const Vec2 gain{-0.05, 0.0};
  const Vec2 near_hit = s.hit({0.51, 0.5}, gain);    // at δ = 0.4 the ray is at u = 0.49: near half
  EXPECT_NEAR(near_hit.x, 0.51 - 0.05 * 0.4, 1e-7);  // δ/W is a float
  const Vec2 far_hit = s.hit({0.9, 0.5}, gain);
  EXPECT_DOUBLE_EQ(far_hit.x, 0.9);
  // From the other side the near half's edge hides nothing: the ray meets the far plane.
  const Vec2 right_eye = s.hit({0.51, 0.5}, {0.05, 0.0});
  EXPECT_DOUBLE_EQ(right_eye.x, 0.51);
}

// The crossing is exact for the nearest-texel surface: on a texel's top where the ray meets its
// value inside it, on its side where the ray enters it below its value.
TEST(DisparitySurface, TheCrossingIsWhereTheRayMeetsTheTexels) {
  ViewDisparity d{100, 10, std::vector<float>(1000, 0.f)};
  for (int y = 0; y < 10; ++y) {
    for (int x = 40; x < 60; ++x) d.d[static_cast<std::size_t>(y) * 100 + x] = 5.f;  // δ/W 0.05
    for (int x = 0; x < 10; ++x) d.d[static_cast<std::size_t>(y) * 100 + x] = 10.f;  // the front, 0.1
  }
  const DisparitySurface s(d);
  const double top = s.values()[50];
  // Within texel 50 from the front (0.1) to the back (0): met at the texel's value.
  const Vec2 on_top = s.hit({0.505, 0.55}, {0.01, 0.0});
  EXPECT_NEAR(on_top.x, 0.505 + 0.01 * top, 1e-15);
  EXPECT_EQ(on_top.y, 0.55);
  // From u = 0.36 at the front to 0.41 at the back: it reaches the block's side (u = 0.40) at
  // δ/W = 0.02, below the block's 0.05, and shows the side there.
  const Vec2 on_side = s.hit({0.41, 0.55}, {-0.5, 0.0});
  EXPECT_NEAR(on_side.x, 0.40, 1e-12);
  // Diagonally through texel corners: the same wall, met where the ray reaches it.
  const Vec2 diagonal = s.hit({0.41, 0.55}, {-0.5, -0.5});
  EXPECT_NEAR(diagonal.x, 0.40, 1e-12);
  EXPECT_NEAR(diagonal.y, 0.55 - 0.5 * 0.02, 1e-12);
}

}  // namespace
}  // namespace nelf
