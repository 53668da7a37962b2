// optics/depth: disparity ↔ distance through the emulated screen's geometry, and the search for
// where a ray meets the content's surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

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

// The float search (the shader's, for the CPU depth-aware composite) finds what the double one
// does, and the batched search (AVX2 eight rays at a time where the CPU has it) exactly what the
// one-ray float search does, for rays across a rough surface and rays far outside the map.
TEST(DisparitySurface, FloatAndBatchedSearchesAgreeWithTheDoubleOne) {
  const int w = 96, h = 54;
  ViewDisparity d{w, h, std::vector<float>(static_cast<std::size_t>(w) * h)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      d.d[static_cast<std::size_t>(y) * w + x] =
          (x / 7 + y / 5) % 3 == 0 ? 9.f : static_cast<float>(3.0 * std::sin(0.3 * x) * std::cos(0.2 * y));
  const DisparitySurface s(d);
  std::vector<float> rays;
  std::uint32_t state = 12345;
  const auto random = [&](float lo, float hi) {
    state = state * 1664525u + 1013904223u;
    return lo + (hi - lo) * static_cast<float>(state >> 8) / static_cast<float>(1u << 24);
  };
  for (int i = 0; i < 1003; ++i) {  // not a multiple of eight: the batch's tail too
    const bool far = i % 50 == 0;
    rays.insert(rays.end(), {far ? random(-40.f, 40.f) : random(0.f, 1.f), random(0.f, 1.f), random(-0.3f, 0.3f),
                             random(-0.3f, 0.3f)});
    // Now and then a ray that does not move: a black pixel's (its map entry -1e9, no gain) or one
    // through the pupil's centre. It meets the surface in the texel it starts in.
    if (i % 37 == 0) rays.insert(rays.end(), {i % 2 ? -1e9f : random(0.f, 1.f), i % 2 ? -1e9f : 0.5f, 0.f, 0.f});
  }
  const int count = static_cast<int>(rays.size() / 4);
  std::vector<float> batched(static_cast<std::size_t>(count));
  s.crossings(rays.data(), count, batched.data());
  int differ_from_double = 0;
  for (int i = 0; i < count; ++i) {
    const float* r = &rays[4 * static_cast<std::size_t>(i)];
    const float one = s.crossing(r[0], r[1], r[2], r[3]);
    ASSERT_EQ(batched[static_cast<std::size_t>(i)], one) << "ray " << i;
    if (r[2] == 0.f && r[3] == 0.f) {
      const int x = std::clamp(static_cast<int>(std::floor(std::max(r[0], -1.f) * w)), 0, w - 1);
      const int y = std::clamp(static_cast<int>(std::floor(std::max(r[1], -1.f) * h)), 0, h - 1);
      EXPECT_EQ(one, s.values()[static_cast<std::size_t>(y) * w + x]) << "ray " << i << " does not move";
      continue;
    }
    const Vec2 exact = s.hit({r[0], r[1]}, {r[2], r[3]});
    const double exact_hit = r[2] != 0.f ? (exact.x - r[0]) / r[2] : 0.0;
    differ_from_double += std::abs(exact_hit - one) > 1e-3 ? 1 : 0;
  }
  // Float and double part only at a tie between two texels' crossings.
  EXPECT_LE(differ_from_double, count / 100);
}

// A tile's front bound is the nearest value of it and its eight neighbours, and no farther.
TEST(DisparitySurface, ATilesFrontBoundIsTheNearestValueAroundIt) {
  constexpr int tile = depth_bound_tile;
  ViewDisparity d{5 * tile, 4 * tile, std::vector<float>(static_cast<std::size_t>(20 * tile * tile), 0.f)};
  d.d[static_cast<std::size_t>(tile + 3) * d.width + 2 * tile + 5] = 8.f;  // in tile (2, 1)
  const DisparitySurface s(d);
  ASSERT_EQ(s.bound_width(), 5);
  ASSERT_EQ(s.bound_height(), 4);
  for (int ty = 0; ty < 4; ++ty)
    for (int tx = 0; tx < 5; ++tx) {
      const bool beside = std::abs(tx - 2) <= 1 && std::abs(ty - 1) <= 1;
      EXPECT_FLOAT_EQ(s.front_bounds()[static_cast<std::size_t>(ty) * 5 + tx], beside ? 8.f / d.width : 0.f)
          << tx << ", " << ty;
    }
}

// The bound holds only within depth_bound_tile − 1 texels of the ray's start: a wall 8 texels on,
// beyond the start tile's neighbours, is met on its side (the whole frame's front).
TEST(DisparitySurface, TheWalkStopsSkippingWhereTheBoundStopsHolding) {
  ASSERT_EQ(depth_bound_tile, 8);
  ViewDisparity d{64, 40, std::vector<float>(64 * 40, 0.f)};
  for (int y = 0; y < 40; ++y)
    for (int x = 32; x < 36; ++x) d.d[static_cast<std::size_t>(y) * 64 + x] = 16.f;  // δ/W 0.25, in tile 4
  const DisparitySurface s(d);
  // At the front the ray is at texel x 23.9 (tile 2: its bound is the background's 0) and moves 64
  // texels per unit of δ/W: it reaches the wall's side at x = 32, u = 0.5.
  const Vec2 side = s.hit({23.9 / 64 + 0.25, 0.5}, {-1.0, 0.0});
  EXPECT_NEAR(side.x, 0.5, 1e-6);
}

// The walk starts at the tile's bound (or where it stops holding) and still finds the front-most
// crossing: against a march along the ray in steps of 1/200000 of the range, on blocks of random
// heights, for rays that cross a texel or two and rays that cross over twenty.
TEST(DisparitySurface, TheWalkFromTheTilesBoundFindsTheCrossingAMarchFinds) {
  constexpr int width = 64, height = 40;
  std::uint32_t seed = 12345;
  const auto random = [&seed] {  // 0..1
    seed = seed * 1664525u + 1013904223u;
    return static_cast<double>(seed >> 8) / static_cast<double>(1u << 24);
  };
  ViewDisparity d{width, height, std::vector<float>(width * height, -2.f)};
  for (int block = 0; block < 12; ++block) {
    const int x0 = static_cast<int>(random() * width), y0 = static_cast<int>(random() * height);
    const int w = 1 + static_cast<int>(random() * 10), h = 1 + static_cast<int>(random() * 10);
    const auto value = static_cast<float>(-2.0 + random() * 20.0);
    for (int y = y0; y < std::min(y0 + h, height); ++y)
      for (int x = x0; x < std::min(x0 + w, width); ++x) d.d[static_cast<std::size_t>(y) * width + x] = value;
  }
  const DisparitySurface s(d);
  const double front = s.front(), back = s.back(), range = front - back;
  const auto value_at = [&](double x, double y) {
    const int tx = std::clamp(static_cast<int>(std::floor(x)), 0, width - 1);
    const int ty = std::clamp(static_cast<int>(std::floor(y)), 0, height - 1);
    return static_cast<double>(s.values()[static_cast<std::size_t>(ty) * width + tx]);
  };
  constexpr int steps = 200'000;
  for (int ray = 0; ray < 60; ++ray) {
    const Vec2 flat{random(), random()};
    const double reach = ray % 2 == 0 ? 0.1 : 2.0;  // a couple of texels, or twenty and more
    const Vec2 gain{(2.0 * random() - 1.0) * reach, (2.0 * random() - 1.0) * reach};
    double hit = back;
    for (int i = 0; i <= steps; ++i) {
      const double t = range * i / steps;
      if (value_at((flat.x + gain.x * (front - t)) * width, (flat.y + gain.y * (front - t)) * height) >= front - t) {
        hit = front - t;
        break;
      }
    }
    const Vec2 walked = s.hit(flat, gain);
    const double tolerance = 2.0 * range / steps * std::max(std::abs(gain.x), std::abs(gain.y)) + 1e-9;
    EXPECT_NEAR(walked.x, flat.x + gain.x * hit, tolerance) << "ray " << ray;
    EXPECT_NEAR(walked.y, flat.y + gain.y * hit, tolerance) << "ray " << ray;
  }
}

}  // namespace
}  // namespace nelf
