// The calibration patterns: geometry derived from the profile, and patterns that are what they
// claim (stripe period, grid line positions, Snellen letter heights).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "inputs/test_patterns.hpp"
#include "optics/mapping.hpp"
#include "optics/profile.hpp"

namespace nelf {
namespace {

bool lit(const Image& image, int x, int y) {
  const Rgba& p = image.at(x, y);
  return p.r + p.g + p.b > 1.5f;
}

// A lens-array profile whose virtual screen is given explicitly: 1000 mm wide at 2000 mm.
Profile explicit_screen_profile() {
  return parse_profile(R"(
name = "explicit"
[display]
resolution = [1280, 720]
pixel_pitch_mm = 0.012
[lens_array]
pitch_mm = 1.0
focal_length_mm = 3.3
[viewing]
eye_relief_mm = 25.0
virtual_image_mm = 1000.0
[screen]
distance_mm = 2000.0
width_mm = 1000.0
)",
                       "explicit.toml");
}

TEST(TestPatterns, NamesParseBothWays) {
  for (const auto& name : test_pattern_names()) {
    const auto p = parse_test_pattern(name);
    ASSERT_TRUE(p) << name;
    EXPECT_EQ(test_pattern_name(*p), name);
  }
  EXPECT_FALSE(parse_test_pattern("stripe"));
  EXPECT_FALSE(parse_test_pattern(""));
}

TEST(TestPatterns, SnellenTwentyTwentyIsFiveArcminutes) {
  const PatternGeometry g = pattern_geometry(explicit_screen_profile());
  EXPECT_DOUBLE_EQ(g.screen_width_mm, 1000.0);
  EXPECT_DOUBLE_EQ(g.screen_distance_mm, 2000.0);
  // By hand: 2000 mm × tan(5') = 2.9089 mm of a 1000 mm wide screen that is 1920 pixels wide.
  EXPECT_NEAR(snellen_letter_height_px(g, 20), 5.585, 0.001);
  EXPECT_NEAR(snellen_letter_height_px(g, 200), 55.85, 0.01);
}

TEST(TestPatterns, SnellenOnHmzT1UsesItsVirtualScreen) {
  const Profile p = load_profile("hmz-t1");
  const PatternGeometry g = pattern_geometry(p);
  const EyeMapping m = make_eye_mapping(p, Eye::left, 16.0 / 9.0);
  EXPECT_DOUBLE_EQ(g.screen_width_mm, m.screen_size_mm.x);
  EXPECT_DOUBLE_EQ(g.screen_distance_mm, 1000.0);
  const double arcmin5 = 5.0 / 60.0 * std::numbers::pi / 180.0;
  EXPECT_NEAR(snellen_letter_height_px(g, 20), 1000.0 * arcmin5 / m.screen_size_mm.x * 1920.0, 1e-3);
  // One display pixel covers many view pixels on this prototype (DESIGN.md §4: ~13).
  EXPECT_GT(g.display_pixel_texels, 8.0);
  EXPECT_LT(g.display_pixel_texels, 20.0);
  // A myope's prescription pulls the screen in to the far point, and the letters grow with it.
  Profile myope = p;
  myope.correction.prescription_diopters = -2.0;
  const PatternGeometry near = pattern_geometry(myope);
  EXPECT_DOUBLE_EQ(near.screen_distance_mm, 500.0);
}

TEST(TestPatterns, SnellenNeedsAScreenSize) {
  const PatternGeometry stock = pattern_geometry(load_profile("hmz-t1-stock"));
  EXPECT_EQ(stock.screen_width_mm, 0.0);
  EXPECT_THROW(snellen_letter_height_px(stock, 20), TestPatternError);
  EXPECT_THROW(make_test_pattern(TestPattern::snellen, stock), TestPatternError);
}

TEST(TestPatterns, SnellenRowsShrinkAndFit) {
  const PatternGeometry g = pattern_geometry(explicit_screen_profile());
  const auto rows = snellen_layout(g);
  ASSERT_GE(rows.size(), 5u);
  for (std::size_t i = 1; i < rows.size(); ++i) {
    EXPECT_LT(rows[i].denominator, rows[i - 1].denominator);
    EXPECT_GT(rows[i].top_px, rows[i - 1].top_px + rows[i - 1].letter_height_px);
  }
  EXPECT_EQ(rows.back().denominator, 20);  // 5.6 px letters still drawn; 20/10 (2.8 px) is not
  EXPECT_LE(rows.back().top_px + rows.back().letter_height_px, g.height);
  for (const auto& row : rows) {
    EXPECT_FALSE(row.letters.empty());
    EXPECT_LE(row.letters.size(), 5u);
    for (char c : row.letters) EXPECT_NE(std::string("CDHKNORSVZ").find(c), std::string::npos);
  }
}

TEST(TestPatterns, SnellenLettersHaveTheirHeight) {
  const PatternGeometry g = pattern_geometry(explicit_screen_profile());
  const StereoPair views = make_test_pattern(TestPattern::snellen, g);
  ASSERT_EQ(views.left.image.width(), 1920);
  ASSERT_EQ(views.left.image.height(), 1080);
  const double label_column = 0.14 * g.width;
  for (const auto& row : snellen_layout(g)) {
    if (row.letter_height_px < 20.0) continue;  // small letters: antialiasing dominates
    // The ink rows of the letters (right of the labels) in this row's band.
    int first = -1, last = -1;
    for (int y = std::max(0, row.top_px - 10); y < std::min(g.height, row.top_px + int(row.letter_height_px) + 10); ++y)
      for (int x = static_cast<int>(label_column); x < g.width; ++x)
        if (views.left.image.at(x, y).r > 0.5f) {
          if (first < 0) first = y;
          last = y;
          break;
        }
    ASSERT_GE(first, 0) << "20/" << row.denominator;
    // Round letters (C, O, S) overshoot the cap height by a few per cent.
    EXPECT_NEAR(last - first + 1, row.letter_height_px, 0.06 * row.letter_height_px + 2) << "20/" << row.denominator;
    EXPECT_NEAR(first, row.top_px, 0.04 * row.letter_height_px + 2) << "20/" << row.denominator;
  }
}

TEST(TestPatterns, StripesHaveTheirPeriod) {
  const PatternGeometry g = pattern_geometry(load_profile("hmz-t1"));
  // Three display pixels per stripe: hmz-t1 shows ~13 view pixels per display pixel.
  EXPECT_EQ(g.stripe_period_px, 2 * static_cast<int>(std::lround(3 * g.display_pixel_texels)));
  const StereoPair views = make_test_pattern(TestPattern::stripes, g);
  const Image& im = views.left.image;
  const int half = g.stripe_period_px / 2;
  // Top half: horizontal stripes (constant along x, alternating along y every half period).
  for (int y = 0; y < g.height / 2; ++y) {
    EXPECT_EQ(lit(im, 0, y), (y / half) % 2 == 0) << y;
    EXPECT_EQ(lit(im, 0, y), lit(im, g.width - 1, y)) << y;
  }
  // Bottom half: vertical stripes.
  for (int x = 0; x < g.width; ++x) {
    EXPECT_EQ(lit(im, x, g.height - 1), (x / half) % 2 == 0) << x;
    EXPECT_EQ(lit(im, x, g.height - 1), lit(im, x, g.height / 2)) << x;
  }
  EXPECT_DOUBLE_EQ(views.left.aspect(), 16.0 / 9.0);
}

TEST(TestPatterns, GridLinesThroughTheCentre) {
  const PatternGeometry g = pattern_geometry(load_profile("hmz-t1-stock"));
  EXPECT_DOUBLE_EQ(g.display_pixel_texels, 1.5);  // 1920 view pixels on 1280 panel pixels
  EXPECT_EQ(g.line_width_px, 2);
  EXPECT_EQ(g.grid_spacing_px, 120);
  const StereoPair views = make_test_pattern(TestPattern::grid, g);
  const Image& im = views.left.image;
  const int y = g.height / 2 + g.grid_spacing_px / 2 + 7;  // a row between horizontal lines, below the cross
  // Vertical lines two pixels wide centred on x = 960 + 120 k.
  int lines = 0;
  for (int x = 0; x < g.width; ++x) {
    const int from_line = ((x - (960 - 1)) % 120 + 120) % 120;
    EXPECT_EQ(lit(im, x, y), from_line < 2) << x;
    lines += from_line == 0;
  }
  EXPECT_EQ(lines, 16);
  // The centre cross is yellow (red and green, no blue) in both eyes; the eyes differ (L / R label).
  for (const Image* eye : {&views.left.image, &views.right.image}) {
    const Rgba c = eye->at(g.width / 2, g.height / 2 + 20);
    EXPECT_GT(c.r, 0.9f);
    EXPECT_GT(c.g, 0.8f);
    EXPECT_LT(c.b, 0.1f);
  }
  long differing = 0;
  for (std::size_t i = 0; i < views.left.image.pixels().size(); ++i)
    differing += views.left.image.pixels()[i].r != views.right.image.pixels()[i].r;
  EXPECT_GT(differing, 100);
}

}  // namespace
}  // namespace nelf
