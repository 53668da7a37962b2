// The formulas of DESIGN.md §2 (optics/optics.hpp) against three geometries whose figures are
// known independently of the code: the hmz-t1 values in DESIGN.md's table, and two geometries worked
// out by hand below (exact fractions where possible, so the expected values are not the code's own).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "optics/optics.hpp"

namespace nelf::optics {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

double degrees(double radians) { return radians * 180.0 / std::acos(-1.0); }

// hmz-t1 (DESIGN.md §8): 1280 × 720 px at 12 µm → 15.36 × 8.64 mm; lens 1 mm / f 3.3 mm;
// d_e 25 mm, d_o 1000 mm.
AxisGeometry hmz(int axis) {
  AxisGeometry g;
  g.display_mm = axis == 0 ? 15.36 : 8.64;
  g.pixel_pitch_mm = 0.012;
  g.lens_pitch_mm = 1.0;
  g.focal_mm = 3.3;
  g.eye_relief_mm = 25.0;
  g.image_mm = 1000.0;
  return g;
}

// Second geometry, by hand: a 1600 × 1200 panel at 10 µm (16 × 12 mm), lens w_l = 2 mm, f = 5 mm,
// d_e = 20 mm, d_o = 500 mm, so d_o − d_e = 480 mm.
//   Eq. 1  d_l = 5 · 480 / 485 = 4.948453608 mm
//   Eq. 2  M = 1 + 480/5 = 97
//   Eq. 6  Δw_s = (20 + d_l)/20 · 2 = 2.494845361 mm;
//          N_l = ⌊16/2.4948⌋ = ⌊6.41⌋ = 6 (even), ⌊12/2.4948⌋ = ⌊4.81⌋ = 4 (even)
//   Eq. 7  lens limit 6·2/40 = 0.3 (display limit 97·16/1000 = 1.552 is larger): α = 2 atan 0.3 = 33.3985°;
//          vertical 4·2/40 = 0.2: α = 2 atan 0.2 = 22.6199°
//   Eq. 8  500·6·2/(20·97·0.01) = 6000/19.4 = 309.28 → 309 (< 1600 px); vertical 4000/19.4 = 206.19 → 206
//   Eq. 9  d_e/d_l = 20·485/(5·480) = 4.0416667; w_e = |500/480 · 2 − 4.0416667 · 2.4948454|
//          = |2.0833333 − 10.0833333| = 8 (= w_l d_e/f whenever Δw_s is not clipped by the display)
//   Eq. 12 lens term |d' − 500|/480 · 2, pixel term (d' − 20) · 0.01/d_l = (d' − 20) · 4.85/2400.
//          d' = 300: lens 200/240 = 0.833333, pixel 280 · 4.85/2400 = 0.565833 → c' = 0.833333
//          d' = 800: lens 300/240 = 1.25, pixel 780 · 4.85/2400 = 1.57625 → c' = 1.57625
//   Eq. 13 d' = 800: ⌊2 · 800 · 0.3 / 1.57625⌋ = ⌊304.52⌋ = 304
//   DoF    a = 2/480 = 10/2400, b = 4.85/2400: near = (500 a + 20 b)/(a + b) = 5097/14.85 = 343.2323 mm;
//          a > b, so far = (500 a − 20 b)/(a − b) = 4903/5.15 = 952.0388 mm
//   Eq. 15 a = 4 mm: ⌊4/2⌋ = 2 at infinity; d_a = 1000: ⌊980/1000 · 4/2⌋ = ⌊1.96⌋ = 1
//   diffraction at 550 nm: 550e-6 · 4.948453608 / 2 mm = 1.360825 µm
AxisGeometry hand(int axis) {
  AxisGeometry g;
  g.display_mm = axis == 0 ? 16.0 : 12.0;
  g.pixel_pitch_mm = 0.01;
  g.lens_pitch_mm = 2.0;
  g.focal_mm = 5.0;
  g.eye_relief_mm = 20.0;
  g.image_mm = 500.0;
  return g;
}

TEST(OpticsHmzT1, GapAndMagnification) {
  EXPECT_NEAR(gap_mm(3.3, 1000, 25), 3.289, 5e-4);
  EXPECT_NEAR(magnification(3.3, 1000, 25), 296.5, 0.05);
}

TEST(OpticsHmzT1, ElementalImageAndLenses) {
  EXPECT_NEAR(elemental_image_mm(hmz(0)), 1.1316, 5e-5);
  EXPECT_EQ(lenses_used(hmz(0)), 13);
  EXPECT_EQ(lenses_used(hmz(1)), 7);
}

TEST(OpticsHmzT1, FieldOfViewResolutionEyeBox) {
  EXPECT_NEAR(degrees(field_of_view_rad(hmz(0))), 29.1, 0.05);
  EXPECT_NEAR(degrees(field_of_view_rad(hmz(1))), 15.9, 0.05);
  EXPECT_EQ(resolution_px(hmz(0)), 146);
  EXPECT_EQ(resolution_px(hmz(1)), 78);
  EXPECT_NEAR(eye_box_mm(hmz(0)), 7.58, 5e-3);
}

TEST(OpticsHmzT1, ViewsInPupil) {
  EXPECT_EQ(views_in_pupil(kInfinity, 25, 4, 1.0), 4);
  // Accommodated at 1 m: ⌊975/1000 · 4⌋ = 3.
  EXPECT_EQ(views_in_pupil(1000, 25, 4, 1.0), 3);
}

TEST(OpticsHmzT1, DepthOfFieldReachesInfinity) {
  // The pixel term grows faster than the lens term (0.012/3.289 > 1/975): no far limit.
  const DepthOfField dof = depth_of_field(hmz(0));
  EXPECT_FALSE(dof.far_mm.has_value());
  // near = (1000/975 + 25 · 0.012/d_l) / (1/975 + 0.012/d_l) with d_l = 3.3 · 975/978.3.
  const double d_l = 3.3 * 975.0 / 978.3, a = 1.0 / 975.0, b = 0.012 / d_l;
  EXPECT_NEAR(dof.near_mm, (1000 * a + 25 * b) / (a + b), 1e-9);
  EXPECT_NEAR(dof.near_mm, 238.94, 0.01);
}

TEST(OpticsHandGeometry, GapAndMagnification) {
  EXPECT_NEAR(gap_mm(5, 500, 20), 4.948453608, 1e-9);
  EXPECT_DOUBLE_EQ(magnification(5, 500, 20), 97.0);
}

TEST(OpticsHandGeometry, EvenLensCounts) {
  EXPECT_NEAR(elemental_image_mm(hand(0)), 2.494845361, 1e-9);
  EXPECT_EQ(lenses_used(hand(0)), 6);
  EXPECT_EQ(lenses_used(hand(1)), 4);
}

TEST(OpticsHandGeometry, FieldOfViewResolutionEyeBox) {
  EXPECT_NEAR(degrees(field_of_view_rad(hand(0))), 33.39849, 1e-4);
  EXPECT_NEAR(degrees(field_of_view_rad(hand(1))), 22.61986, 1e-4);
  EXPECT_EQ(resolution_px(hand(0)), 309);
  EXPECT_EQ(resolution_px(hand(1)), 206);
  EXPECT_NEAR(eye_box_mm(hand(0)), 8.0, 1e-9);
  EXPECT_NEAR(eye_box_mm(hand(1)), 8.0, 1e-9);
}

TEST(OpticsHandGeometry, ResolutionLimitedByLensesOrPixels) {
  // A 1.6 mm strip of the hand panel behind 1 mm lenses: Δw_s = 24.948/20 = 1.2474 → N_l = 1.
  AxisGeometry g = hand(0);
  g.display_mm = 1.6;
  g.lens_pitch_mm = 1.0;
  EXPECT_EQ(lenses_used(g), 1);
  // Lens limit 500 · 1 · 1/(20 · 97 · 0.01) = 25.77 → 25, below the strip's 160 px.
  EXPECT_EQ(resolution_px(g), 25);
  // 0.1 mm pixels: lens limit 500/194 = 2.577 → 2, the strip has 16 px.
  g.pixel_pitch_mm = 0.1;
  EXPECT_EQ(resolution_px(g), 2);
  // f = 100 mm: M = 1 + 480/100 = 5.8, lens limit 500/(20 · 5.8 · 0.1) = 43.1 > 16 px: the pixels limit.
  g.focal_mm = 100;
  EXPECT_EQ(resolution_px(g), 16);
}

TEST(OpticsHandGeometry, DefocusBlurAndResolutionAtDepth) {
  EXPECT_NEAR(defocus_blur_mm(hand(0), 300), 0.8333333333, 1e-9);       // lens term wins (nearer than d_o)
  EXPECT_NEAR(defocus_blur_mm(hand(0), 800), 1.57625, 1e-9);            // pixel term wins
  EXPECT_NEAR(defocus_blur_mm(hand(0), 500), 480 * 4.85 / 2400, 1e-9);  // in focus: only the pixel
  EXPECT_EQ(resolution_at_depth_px(hand(0), 800), 304);
}

TEST(OpticsHandGeometry, DepthOfFieldHasBothEnds) {
  const DepthOfField dof = depth_of_field(hand(0));
  EXPECT_NEAR(dof.near_mm, 5097.0 / 14.85, 1e-9);
  ASSERT_TRUE(dof.far_mm.has_value());
  EXPECT_NEAR(*dof.far_mm, 4903.0 / 5.15, 1e-9);
  // At both ends the two terms of Eq. 12 are equal, inside the lens term is the smaller.
  const double lens_at_near = (500 - dof.near_mm) / 480 * 2, pixel_at_near = (dof.near_mm - 20) * 4.85 / 2400;
  EXPECT_NEAR(lens_at_near, pixel_at_near, 1e-12);
  EXPECT_NEAR(defocus_blur_mm(hand(0), 700), (700 - 20) * 4.85 / 2400, 1e-12);
}

TEST(OpticsHandGeometry, ViewsAndDiffraction) {
  EXPECT_EQ(views_in_pupil(kInfinity, 20, 4, 2), 2);
  EXPECT_EQ(views_in_pupil(1000, 20, 4, 2), 1);
  EXPECT_NEAR(diffraction_pitch_um(550, gap_mm(5, 500, 20), 2), 1.360825, 1e-6);
  EXPECT_NEAR(diffraction_pitch_um(390, 3.3, 1.0), 1.287, 1e-12);
}

TEST(Optics, FixedGapUsesThinLensMagnification) {
  // A hardware gap of 3 mm behind f = 3.3 mm: M = 3.3/0.3 = 11, no longer Eq. 2's 296.5. With M = 11 the
  // display limit of Eq. 7 (11 · 15.36/2000 = 0.0845) is below the lens limit (13 · 1/50 = 0.26).
  AxisGeometry g = hmz(0);
  g.gap_mm = 3.0;
  EXPECT_NEAR(elemental_image_mm(g), 28.0 / 25.0, 1e-12);
  EXPECT_NEAR(field_of_view_rad(g), 2 * std::atan(11 * 15.36 / 2000), 1e-12);
  // Eq. 8: 1000 · 13 / (25 · 11 · 0.012) = 3939 > 1280 px: the panel limits.
  EXPECT_EQ(resolution_px(g), 1280);
}

TEST(Optics, EyeBlur) {
  // Eq. 14: accommodated at 500 mm, a point at 1000 mm through a 4 mm pupil: 500/500 · 4 = 4 mm.
  EXPECT_DOUBLE_EQ(eye_blur_mm(500, 1000, 4), 4.0);
  EXPECT_DOUBLE_EQ(eye_blur_mm(1000, 500, 4), 2.0);
  EXPECT_DOUBLE_EQ(eye_blur_mm(800, 800, 4), 0.0);
}

TEST(Optics, SimpleMagnifierBound) {
  // f-number 2, eye box 8 mm, d_e 20 mm, w_s 16 mm: (16 + √(256 + 4 · 2 · 20 · 16))/2 = (16 + √2816)/2.
  const double f = simple_magnifier_min_focal_mm(2, 8, 20, 16);
  EXPECT_NEAR(f, (16 + std::sqrt(2816.0)) / 2, 1e-12);
  EXPECT_NEAR(f, 34.533, 1e-3);
  // The bound is where a lens of width f/N has exactly that eye box: w_e = f/N − d_e w_s / f.
  EXPECT_NEAR(f / 2 - 20 * 16 / f, 8.0, 1e-9);
  // hmz-t1 panel at f/1 with a 10 mm eye box: (10 + √(100 + 1536))/2.
  EXPECT_NEAR(simple_magnifier_min_focal_mm(1, 10, 25, 15.36), (10 + std::sqrt(1636.0)) / 2, 1e-12);
}

// A single magnifier by hand: 16 × 12 mm panel at 10 µm, lens 20 mm wide, f = 40 mm, d_e 20, d_o 2000.
//   d_l = 40 · 1980/2020 = 39.207921, M = 1 + 1980/40 = 50.5
//   α: lens limit 20/40 = 0.5, display limit 50.5 · 16/4000 = 0.202 → 2 atan 0.202 = 22.84015°;
//      vertical 50.5 · 12/4000 = 0.1515 → 17.22960°
//   N_p: lens 2000 · 20/(20 · 50.5 · 0.01) = 3960 > 1600 px → 1600; vertical 1200
//   w_e = |2000/1980 · 20 − 20/d_l · 16| = 20.202020 − 8.161616 = 12.040404; vertical − 6.121212 → 14.080808
TEST(OpticsMagnifier, SingleLensByHand) {
  AxisGeometry g;
  g.display_mm = 16;
  g.pixel_pitch_mm = 0.01;
  g.lens_pitch_mm = 20;
  g.focal_mm = 40;
  g.eye_relief_mm = 20;
  g.image_mm = 2000;
  AxisGeometry v = g;
  v.display_mm = 12;
  EXPECT_NEAR(degrees(magnifier::field_of_view_rad(g)), 22.840148, 1e-5);
  EXPECT_NEAR(degrees(magnifier::field_of_view_rad(v)), 17.229599, 1e-5);
  EXPECT_EQ(magnifier::resolution_px(g), 1600);
  EXPECT_EQ(magnifier::resolution_px(v), 1200);
  EXPECT_NEAR(magnifier::eye_box_mm(g), 12.040404040, 1e-8);
  EXPECT_NEAR(magnifier::eye_box_mm(v), 14.080808081, 1e-8);
  // A lens narrower than the field the display fills: the lens limits α (w_l/(2 d_e) = 0.1).
  g.lens_pitch_mm = 4;
  EXPECT_NEAR(magnifier::field_of_view_rad(g), 2 * std::atan(0.1), 1e-12);
  // and the resolution: 2000 · 4/(20 · 50.5 · 0.01) = 792.08 → 792.
  EXPECT_EQ(magnifier::resolution_px(g), 792);
}

TEST(OpticsMagnifier, IsTheLensArrayModelWithOneLensFillingTheDisplay) {
  // When one lens's elemental image covers the display (Δw_s clipped to w_s, N_l = 1), the array
  // formulas and the magnifier formulas must agree.
  AxisGeometry g = hand(0);
  g.lens_pitch_mm = 14.0;  // (20 + d_l)/20 · 14 = 17.46 > 16 mm: clipped, one lens
  ASSERT_EQ(lenses_used(g), 1);
  EXPECT_DOUBLE_EQ(field_of_view_rad(g), magnifier::field_of_view_rad(g));
  EXPECT_EQ(resolution_px(g), magnifier::resolution_px(g));
  EXPECT_DOUBLE_EQ(eye_box_mm(g), magnifier::eye_box_mm(g));
}

TEST(OpticsConversions, CountsOutOfIntRangeThrowInsteadOfOverflowing) {
  EXPECT_EQ(floor_to_int(2.9999, "x"), 2);
  EXPECT_EQ(floor_to_int(-0.5, "x"), -1);
  EXPECT_EQ(floor_to_int(2147483647.5, "x"), 2147483647);
  for (double bad : {std::nan(""), kInfinity, -kInfinity, 2147483648.0, -2147483649.0, 1e300})
    EXPECT_THROW(floor_to_int(bad, "x"), std::range_error) << bad;
  // 1e9 mm pixels (the absurd profile of issue #11): 1.28e12 mm of panel under 1 mm lenses is
  // more lenses than an int holds; it used to come out as -2147483648 and a -180 deg field of view.
  AxisGeometry g = hmz(0);
  g.pixel_pitch_mm = 1e9;
  g.display_mm = 1280 * 1e9;
  EXPECT_GT(lenses_fitting(g), 1e11);
  EXPECT_THROW(lenses_used(g), std::range_error);
  EXPECT_THROW(field_of_view_rad(g), std::range_error);
  EXPECT_THROW(resolution_px(g), std::range_error);
  // Views in the pupil: a 1e300 mm pupil over 1 mm lenses.
  EXPECT_THROW(views_in_pupil(kInfinity, 25.0, 1e300, 1.0), std::range_error);
  EXPECT_EQ(views_in_pupil(kInfinity, 25.0, 4.0, 1.0), 4);
}

}  // namespace
}  // namespace nelf::optics
