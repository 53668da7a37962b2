#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "optics/defect_compensation.hpp"
#include "optics/profile.hpp"
#include "support/defect_maps.hpp"

namespace nelf {
namespace {

const EyeMapping& hmz_t1_left() {
  static const EyeMapping m = make_eye_mapping(load_profile("hmz-t1"), Eye::left, 16.0 / 9.0);
  return m;
}

// A lit pixel near the middle of the panel (the centre of the elemental image of the lens there).
std::array<int, 2> central_lit_pixel(const EyeMapping& m) {
  for (int y = m.panel[1] / 2; y < m.panel[1]; ++y)
    if (view_coordinate_at_pixel(m, m.panel[0] / 2 + 0.5, y + 0.5)) return {m.panel[0] / 2, y};
  return {-1, -1};
}

PixelDefect dead(Eye eye, std::array<int, 2> p) { return {eye, p[0], p[1], DefectKind::dead, {0, 0, 0}}; }

TEST(DefectCompensation, EyeBoxIsEquationNine) {
  // DESIGN.md §2: 7.58 mm for hmz-t1.
  EXPECT_NEAR(eye_box_width_mm(hmz_t1_left()), 7.58, 0.01);
  const auto grid = eye_box_pupil_positions(hmz_t1_left(), 4.0, 3);
  ASSERT_EQ(grid.size(), 9u);
  EXPECT_NEAR(grid.front().x, -(7.58 - 4.0) / 2, 0.01);
  EXPECT_NEAR(grid.back().y, (7.58 - 4.0) / 2, 0.01);
  EXPECT_EQ(grid[4].x, 0.0);
  // A pupil larger than the eye box is kept at the centre only.
  for (const Vec2& q : eye_box_pupil_positions(hmz_t1_left(), 9.0, 3)) EXPECT_EQ(q.x, 0.0);
}

TEST(DefectCompensation, ADeadPixelIsSharedOverItsBundleWithBoundedNonNegativeWeights) {
  const EyeMapping& m = hmz_t1_left();
  const auto p = central_lit_pixel(m);
  ASSERT_GE(p[1], 0);
  const DefectMap map{{dead(Eye::left, p)}};
  const EyeDefectPlan plan = plan_defect_compensation(m, map);
  EXPECT_EQ(plan.eye, Eye::left);
  EXPECT_EQ(plan.panel, m.panel);
  EXPECT_EQ(plan.outside_lit, 0);
  EXPECT_EQ(plan.uncompensable, 0);
  ASSERT_EQ(plan.corrections.size(), 1u);
  const DefectCorrection& c = plan.corrections[0];
  EXPECT_EQ(c.defect, map.defects[0]);
  ASSERT_GE(c.shares.size(), 8u);  // at least the ring of neighbouring lenses
  double total = 0;
  std::set<std::pair<int, int>> pixels;
  const auto candidates = defect_bundle_pixels(m, p[0], p[1]);
  for (const BundleShare& s : c.shares) {
    EXPECT_GT(s.weight, 0.f);
    EXPECT_LE(s.weight, 1.f);
    EXPECT_FALSE(s.x == p[0] && s.y == p[1]);
    EXPECT_TRUE(pixels.insert({s.x, s.y}).second) << "pixel given twice";
    EXPECT_NE(std::find(candidates.begin(), candidates.end(), std::array<int, 2>{s.x, s.y}), candidates.end());
    // Each share shows (nearly) the defect's screen point: within a pixel's footprint of it.
    const auto uv = view_coordinate_at_pixel(m, s.x + 0.5, s.y + 0.5);
    const auto uv_defect = view_coordinate_at_pixel(m, p[0] + 0.5, p[1] + 0.5);
    ASSERT_TRUE(uv && uv_defect);
    const Vec2 footprint = pixel_footprint_uv(m);
    EXPECT_LE(std::abs(uv->x - uv_defect->x), 1.5 * footprint.x);
    EXPECT_LE(std::abs(uv->y - uv_defect->y), 1.5 * footprint.y);
    total += s.weight;
  }
  // The neighbours' beams each carry about as much of the pupil as the defect's: together they send
  // about one pixel's worth of light.
  EXPECT_GT(total, 0.6);
  EXPECT_LT(total, 1.6);
}

TEST(DefectCompensation, ADefectOutsideTheLitElementalImagesNeedsNothing) {
  const EyeMapping& m = hmz_t1_left();
  ASSERT_FALSE(view_coordinate_at_pixel(m, 0.5, 0.5));  // the corner of the panel is not lit
  const EyeDefectPlan plan = plan_defect_compensation(
      m, DefectMap{{dead(Eye::left, {0, 0}), {Eye::left, 1, 0, DefectKind::stuck, {255, 255, 255}}}});
  EXPECT_EQ(plan.outside_lit, 2);
  EXPECT_EQ(plan.uncompensable, 0);
  EXPECT_TRUE(plan.empty());
}

TEST(DefectCompensation, AStuckPixelBesideTheLitBlockWhoseLensShowsTheScreenIsMadeUp) {
  // Left 451 14 on hmz-t1 (from docs/defects.md's seed-1 map): outside the lit elemental images, so
  // it is sent black, but stuck white it sends light through the lens in front of it to a point of
  // the screen, seen from the eye box's edge. Dead there, it shows what it is sent: nothing to do.
  const EyeMapping& m = hmz_t1_left();
  ASSERT_FALSE(view_coordinate_at_pixel(m, 451.5, 14.5));
  const EyeDefectPlan stuck =
      plan_defect_compensation(m, DefectMap{{{Eye::left, 451, 14, DefectKind::stuck, {255, 255, 255}}}});
  EXPECT_EQ(stuck.outside_lit, 0);
  ASSERT_EQ(stuck.corrections.size(), 1u);
  EXPECT_GE(stuck.corrections[0].shares.size(), 2u);
  for (const BundleShare& share : stuck.corrections[0].shares)
    EXPECT_TRUE(view_coordinate_at_pixel(m, share.x + 0.5, share.y + 0.5)) << "a share on an unlit pixel";
  const EyeDefectPlan dead_there = plan_defect_compensation(m, DefectMap{{dead(Eye::left, {451, 14})}});
  EXPECT_EQ(dead_there.outside_lit, 1);
  EXPECT_TRUE(dead_there.empty());
}

TEST(DefectCompensation, TheOtherEyesDefectsAreNotPlanned) {
  const EyeMapping& m = hmz_t1_left();
  const EyeDefectPlan plan = plan_defect_compensation(m, DefectMap{{dead(Eye::right, central_lit_pixel(m))}});
  EXPECT_TRUE(plan.empty());
  EXPECT_EQ(plan.outside_lit + plan.uncompensable, 0);
}

TEST(DefectCompensation, OtherDefectsAreLeftOutOfABundleAndABundleWithNoHealthyPixelIsCounted) {
  const EyeMapping& m = hmz_t1_left();
  const auto p = central_lit_pixel(m);
  const auto bundle = defect_bundle_pixels(m, p[0], p[1]);
  ASSERT_GE(bundle.size(), 24u);
  DefectMap map{{dead(Eye::left, p)}};
  // Half the bundle defective: the rest still compensates, and none of the defects gets a share.
  for (std::size_t k = 0; k < bundle.size(); k += 2) map.defects.push_back(dead(Eye::left, bundle[k]));
  std::set<std::pair<int, int>> defective;
  for (const PixelDefect& d : map.defects) defective.insert({d.x, d.y});
  EyeDefectPlan plan = plan_defect_compensation(m, map);
  ASSERT_FALSE(plan.corrections.empty());
  ASSERT_EQ(plan.corrections[0].defect, map.defects[0]);
  EXPECT_FALSE(plan.corrections[0].shares.empty());
  for (const DefectCorrection& c : plan.corrections)
    for (const BundleShare& s : c.shares) EXPECT_FALSE(defective.contains({s.x, s.y}));
  // All of it defective: the first defect cannot be made up for, and is counted.
  for (std::size_t k = 1; k < bundle.size(); k += 2) map.defects.push_back(dead(Eye::left, bundle[k]));
  plan = plan_defect_compensation(m, map);
  EXPECT_GE(plan.uncompensable, 1);
  for (const DefectCorrection& c : plan.corrections) EXPECT_NE(c.defect, map.defects[0]);
  EXPECT_EQ(static_cast<int>(plan.corrections.size()) + plan.uncompensable + plan.outside_lit,
            static_cast<int>(map.defects.size()));
}

TEST(DefectCompensation, AStockDeviceHasNoBundles) {
  const Profile stock = load_profile("hmz-t1-stock");
  const EyeMapping m = make_eye_mapping(stock, Eye::left, 16.0 / 9.0);
  const EyeDefectPlan plan = plan_defect_compensation(m, DefectMap{{dead(Eye::left, {640, 360})}});
  EXPECT_EQ(plan.uncompensable, 1);
  EXPECT_TRUE(plan.empty());
  EXPECT_TRUE(defect_bundle_pixels(m, 640, 360).empty());
  EXPECT_EQ(eye_box_width_mm(m), 0.0);
}

TEST(DefectCompensation, AThousandDefectsAllGetAPlan) {
  const EyeMapping& m = hmz_t1_left();
  // About 1000 of hmz-t1's lit pixels.
  const DefectMap map = test::random_defect_map(m, 1000.0 / (m.panel[0] * m.panel[1] * lit_fraction(m)), 0.0, 7);
  ASSERT_GT(map.defects.size(), 900u);
  ASSERT_LT(map.defects.size(), 1100u);
  // (How long planning takes is measured by hand, not bounded here: about 0.1 s, docs/defects.md.)
  const EyeDefectPlan plan = plan_defect_compensation(m, map);
  EXPECT_EQ(plan.outside_lit, 0);
  EXPECT_GT(plan.corrections.size(), map.defects.size() * 9 / 10);
  std::size_t shares = 0;
  for (const DefectCorrection& c : plan.corrections) shares += c.shares.size();
  EXPECT_GT(shares, plan.corrections.size());
}

}  // namespace
}  // namespace nelf
