// The keys of `nelf calibrate`: key sequences give exact profile values, limits hold, and what
// would be saved loads back with the adjusted values.
#include <gtest/gtest.h>

#include "compositor/calibration_controls.hpp"
#include "compositor/mapping.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using Named = KeyPress::Named;

KeyPress key(char32_t c) { return KeyPress::of(c); }
KeyPress key(Named n, bool shift = false) {
  KeyPress k = KeyPress::of(n);
  k.shift = shift;
  return k;
}

CalibrationStep press(CalibrationControls& c, const std::vector<KeyPress>& keys) {
  CalibrationStep last;
  for (const auto& k : keys) last = c.apply(k);
  return last;
}

const Vec2& shift_of(const CalibrationControls& c, Eye eye) { return c.profile().eye_calibration(eye).shift_px; }

TEST(CalibrationControls, ArrowsShiftBothEyesThenTheSelectedOne) {
  CalibrationControls c(load_profile("hmz-t1"), TestPattern::stripes);
  EXPECT_EQ(c.selected_eye(), CalibrationEye::both);
  auto step = press(c, {key(Named::right), key(Named::right), key(Named::down)});
  EXPECT_TRUE(step.profile_changed);
  EXPECT_EQ(shift_of(c, Eye::left), (Vec2{2.0, 1.0}));
  EXPECT_EQ(shift_of(c, Eye::right), (Vec2{2.0, 1.0}));
  EXPECT_EQ(step.message, "left shift 2.0, 1.0 px; right shift 2.0, 1.0 px");

  step = c.apply(key(Named::tab));
  EXPECT_FALSE(step.profile_changed);
  EXPECT_EQ(c.selected_eye(), CalibrationEye::left);
  EXPECT_EQ(step.message, "adjusting left eye");
  press(c, {key(Named::left, true), key(Named::left, true), key(Named::left, true), key(Named::up)});
  EXPECT_EQ(shift_of(c, Eye::left), (Vec2{1.7, 0.0}));
  EXPECT_EQ(shift_of(c, Eye::right), (Vec2{2.0, 1.0}));

  c.apply(key(Named::tab));
  EXPECT_EQ(c.selected_eye(), CalibrationEye::right);
  press(c, {key(Named::up, true)});
  EXPECT_EQ(shift_of(c, Eye::right), (Vec2{2.0, 0.9}));
  EXPECT_EQ(shift_of(c, Eye::left), (Vec2{1.7, 0.0}));
  c.apply(key(Named::tab));
  EXPECT_EQ(c.selected_eye(), CalibrationEye::both);
}

TEST(CalibrationControls, RotationPitchScaleAndTheirSteps) {
  CalibrationControls c(load_profile("hmz-t1"), TestPattern::stripes);
  for (int i = 0; i < 7; ++i) c.apply(key(U'R'));
  c.apply(key(U'r'));
  EXPECT_EQ(c.profile().eye_calibration(Eye::left).rotation_deg, 0.3);
  EXPECT_EQ(c.profile().eye_calibration(Eye::right).rotation_deg, 0.3);
  c.apply(key(Named::tab));  // left only
  const auto step = press(c, {key(U'p'), key(U'p'), key(U'p')});
  EXPECT_EQ(step.message, "left pitch scale 0.9985");
  EXPECT_EQ(c.profile().eye_calibration(Eye::left).pitch_scale, 0.9985);
  EXPECT_EQ(c.profile().eye_calibration(Eye::right).pitch_scale, 1.0);
  // The lens array's own rotation is not touched: calibration adds to it.
  EXPECT_EQ(c.profile().lens_array->rotation_deg, 0.0);
}

TEST(CalibrationControls, GapStartsFromEquationOneWhenImplicit) {
  const Profile start = load_profile("hmz-t1");
  ASSERT_FALSE(start.lens_array->gap_mm);
  const double derived = lens_gap_mm(start);  // ≈ 3.289 mm
  CalibrationControls c(start, TestPattern::grid);
  c.apply(key(U'G'));
  ASSERT_TRUE(c.profile().lens_array->gap_mm);
  EXPECT_NEAR(*c.profile().lens_array->gap_mm, derived + 0.005, 1e-6);
  c.apply(key(U'g'));
  c.apply(key(U'g'));
  EXPECT_NEAR(*c.profile().lens_array->gap_mm, derived - 0.005, 1e-6);
}

TEST(CalibrationControls, IpdAndPrescription) {
  CalibrationControls c(load_profile("hmz-t1"), TestPattern::grid);
  press(c, {key(U']'), key(U']'), key(U']'), key(U'[')});
  EXPECT_EQ(c.profile().viewing.ipd_mm, 64.0);
  auto step = press(c, {key(U'd'), key(U'd'), key(U'd'), key(U'd'), key(U'd'), key(U'd'), key(U'd'), key(U'd')});
  EXPECT_EQ(c.profile().correction.prescription_diopters, -2.0);
  EXPECT_EQ(step.message, "prescription -2.00 D (screen at 500 mm)");
  c.apply(key(U'D'));
  EXPECT_EQ(c.profile().correction.prescription_diopters, -1.75);
}

TEST(CalibrationControls, LimitsKeepTheProfileValid) {
  CalibrationControls c(load_profile("hmz-t1"), TestPattern::stripes);
  for (int i = 0; i < 100; ++i) c.apply(key(U'D'));
  EXPECT_EQ(c.profile().correction.prescription_diopters, 20.0);
  const auto step = c.apply(key(U'D'));
  EXPECT_FALSE(step.profile_changed);
  EXPECT_NE(step.message.find("(limit)"), std::string::npos);
  for (int i = 0; i < 200; ++i) c.apply(key(U'['));
  EXPECT_EQ(c.profile().viewing.ipd_mm, 40.0);
  for (int i = 0; i < 1000; ++i) c.apply(key(U'G'));
  // The gap stays below the focal length (a virtual image), as parse_profile demands.
  EXPECT_LT(*c.profile().lens_array->gap_mm, c.profile().lens_array->focal_length_mm);
  for (int i = 0; i < 1000; ++i) c.apply(key(Named::left));
  EXPECT_EQ(shift_of(c, Eye::left).x, -640.0);
  EXPECT_NO_THROW(parse_profile(profile_to_toml(c.profile()), "limits.toml"));
}

TEST(CalibrationControls, AChangeTheGeometryCannotShowIsRefused) {
  // A strong myopic prescription pulls the screen in to the far point; closer than ~120 mm no
  // screen fits both eyes' field of view on hmz-t1 (the screen converges half the IPD inwards).
  // The key that would go there is refused and the profile stays usable.
  CalibrationControls c(load_profile("hmz-t1"), TestPattern::grid);
  CalibrationStep step;
  int accepted = 0;
  for (int i = 0; i < 80 && (accepted == 0 || step.profile_changed); ++i) {
    step = c.apply(key(U'd'));
    accepted += step.profile_changed;
  }
  EXPECT_GT(accepted, 4);
  EXPECT_FALSE(step.profile_changed);
  EXPECT_EQ(step.message.rfind("not changed: ", 0), 0u) << step.message;
  EXPECT_NE(step.message.find("no screen fits"), std::string::npos) << step.message;
  const double last = c.profile().correction.prescription_diopters;
  EXPECT_GT(last, -20.0);
  EXPECT_NO_THROW(make_eye_mapping(c.profile(), Eye::left, 16.0 / 9.0));
  // Back the other way works again.
  EXPECT_TRUE(c.apply(key(U'D')).profile_changed);
  EXPECT_EQ(c.profile().correction.prescription_diopters, last + 0.25);
}

TEST(CalibrationControls, StockProfileHasNoPitchOrGap) {
  CalibrationControls c(load_profile("hmz-t1-stock"), TestPattern::grid);
  auto step = c.apply(key(U'P'));
  EXPECT_FALSE(step.profile_changed);
  EXPECT_EQ(step.message, "pitch scale: this profile has no lens array");
  step = c.apply(key(U'G'));
  EXPECT_FALSE(step.profile_changed);
  step = c.apply(key(U'3'));
  EXPECT_FALSE(step.pattern_changed);
  EXPECT_EQ(c.pattern(), TestPattern::grid);
  EXPECT_EQ(step.message, "no Snellen chart: the screen size is unknown");
  step = c.apply(key(U'R'));
  EXPECT_TRUE(step.profile_changed);
  EXPECT_EQ(c.profile().eye_calibration(Eye::right).rotation_deg, 0.05);
}

TEST(CalibrationControls, PatternsSaveHelpQuit) {
  CalibrationControls c(load_profile("hmz-t1"), TestPattern::stripes);
  auto step = c.apply(key(U'3'));
  EXPECT_TRUE(step.pattern_changed);
  EXPECT_FALSE(step.profile_changed);
  EXPECT_EQ(c.pattern(), TestPattern::snellen);
  EXPECT_EQ(step.message, "pattern snellen");
  EXPECT_FALSE(c.apply(key(U'3')).pattern_changed);
  c.apply(key(U'2'));
  EXPECT_EQ(c.pattern(), TestPattern::grid);
  c.apply(key(U'4'));
  EXPECT_EQ(c.pattern(), TestPattern::white);
  c.apply(key(U'1'));
  EXPECT_EQ(c.pattern(), TestPattern::stripes);
  EXPECT_TRUE(c.apply(key(U'w')).save);
  EXPECT_TRUE(c.apply(key(U'h')).help);
  EXPECT_TRUE(c.apply(key(U'q')).quit);
  EXPECT_TRUE(c.apply(key(Named::escape)).quit);
  KeyPress ctrl_c = key(U'c');
  ctrl_c.ctrl = true;
  EXPECT_TRUE(c.apply(ctrl_c).quit);
  KeyPress ctrl_r = key(U'r');
  ctrl_r.ctrl = true;
  EXPECT_FALSE(c.apply(ctrl_r).profile_changed);
  step = c.apply(key(U'x'));
  EXPECT_FALSE(step.profile_changed || step.pattern_changed || step.quit || step.save);
  EXPECT_EQ(step.message, "key 'x' does nothing (h: help)");
  EXPECT_FALSE(CalibrationControls::help_lines().empty());
}

TEST(CalibrationControls, SavedProfileLoadsWithTheAdjustedValues) {
  CalibrationControls c(load_profile("hmz-t1"), TestPattern::stripes);
  press(c, {key(Named::right), key(Named::tab), key(U'R'), key(U'R'), key(U'P'), key(Named::tab),
            key(Named::down, true), key(U'G'), key(U']'), key(U'd')});
  test::TempDir dir;
  const auto path = dir / "mine.toml";
  test::write_file(path, profile_to_toml(c.profile()));
  const Profile saved = load_profile(path.string());
  EXPECT_EQ(saved.eye_calibration(Eye::left).shift_px, (Vec2{1.0, 0.0}));
  EXPECT_EQ(saved.eye_calibration(Eye::left).rotation_deg, 0.1);
  EXPECT_EQ(saved.eye_calibration(Eye::left).pitch_scale, 1.0005);
  EXPECT_EQ(saved.eye_calibration(Eye::right).shift_px, (Vec2{1.0, 0.1}));
  EXPECT_EQ(saved.eye_calibration(Eye::right).rotation_deg, 0.0);
  EXPECT_EQ(saved.eye_calibration(Eye::right).pitch_scale, 1.0);
  EXPECT_EQ(*saved.lens_array->gap_mm, *c.profile().lens_array->gap_mm);
  EXPECT_EQ(saved.viewing.ipd_mm, 63.5);
  EXPECT_EQ(saved.correction.prescription_diopters, -0.25);
  EXPECT_EQ(saved.name, "hmz-t1");
}

}  // namespace
}  // namespace nelf
