// The keys of `nelf calibrate`: key sequences give exact profile values, limits hold, and what
// would be saved loads back with the adjusted values.
#include <gtest/gtest.h>

#include "compositor/reference.hpp"
#include "optics/mapping.hpp"
#include "player/calibration_controls.hpp"
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

// The fraction of the reference compositor's frame that is lit (not black) for a white pattern:
// what the eye actually gets to see, measured on the composited pixels rather than the mapping.
double lit_fraction_of_frame(const Profile& profile, Eye eye) {
  const EyeMapping m = make_eye_mapping(profile, eye, 16.0 / 9.0);
  Image white(64, 36);
  for (Rgba& px : white.pixels()) px = Rgba{1.f, 1.f, 1.f, 1.f};
  const Image frame = reference_eye_image(m, white, 1);
  std::size_t lit = 0;
  for (int y = 0; y < frame.height(); ++y)
    for (int x = 0; x < frame.width(); ++x) lit += frame.at(x, y).g > 0.5f;
  return static_cast<double>(lit) / (static_cast<double>(frame.width()) * frame.height());
}

TEST(CalibrationControls, MyopicPrescriptionStopsBeforeTheFrameGoesDark) {
  // A myopic prescription pulls the screen in to the far point, where it shrinks to a patch: on
  // hmz-t1 -4 D already left 40% of the light, -8.25 D an all-black frame that was saved. The
  // keys stop, with the reason, while at least 15% of each eye's panel shows the screen.
  CalibrationControls c(load_profile("hmz-t1"), TestPattern::white);
  const double start = lit_fraction_of_frame(c.profile(), Eye::left);
  EXPECT_GT(start, 0.4);
  EXPECT_NEAR(c.lit_fraction(), start, 0.02);
  CalibrationStep step;
  int accepted = 0;
  for (int i = 0; i < 80; ++i) {
    step = c.apply(key(U'd'));
    if (!step.profile_changed) break;
    ++accepted;
  }
  EXPECT_GT(accepted, 4);
  EXPECT_FALSE(step.profile_changed);
  EXPECT_EQ(step.message.rfind("not changed: ", 0), 0u) << step.message;
  EXPECT_NE(step.message.find("of the panel would show the screen (at least 15%)"), std::string::npos) << step.message;
  const double last = c.profile().correction.prescription_diopters;
  EXPECT_LT(last, -2.0);
  EXPECT_GT(last, -8.0);
  // What is kept still shows a picture, measured on the composited frame; one more step would not.
  for (Eye eye : {Eye::left, Eye::right}) EXPECT_GE(lit_fraction_of_frame(c.profile(), eye), 0.14);
  Profile darker = c.profile();
  darker.correction.prescription_diopters -= CalibrationControls::prescription_step_diopters;
  EXPECT_LT(std::min(lit_fraction_of_frame(darker, Eye::left), lit_fraction_of_frame(darker, Eye::right)), 0.16);
  // The same refusal on every further press; back the other way works again.
  EXPECT_FALSE(c.apply(key(U'd')).profile_changed);
  EXPECT_TRUE(c.apply(key(U'D')).profile_changed);
  EXPECT_EQ(c.profile().correction.prescription_diopters, last + 0.25);
}

TEST(CalibrationControls, ShiftsThatPushTheImageOffThePanelStop) {
  // Both eyes shifted towards a corner: the lit area shrinks to a quarter of what it was before
  // the limit of half the panel in both directions.
  CalibrationControls c(load_profile("hmz-t1"), TestPattern::white);
  CalibrationStep step;
  for (int i = 0; i < 400; ++i) c.apply(key(Named::up));
  EXPECT_EQ(shift_of(c, Eye::left).y, -360.0) << "half the panel up still shows half the screen";
  for (int i = 0; i < 700; ++i)
    if (!(step = c.apply(key(Named::left))).profile_changed) break;
  EXPECT_FALSE(step.profile_changed);
  EXPECT_GT(shift_of(c, Eye::left).x, -640.0) << "stopped before the key's own limit";
  EXPECT_NE(step.message.find("would show the screen"), std::string::npos) << step.message;
  EXPECT_GE(c.lit_fraction(), CalibrationControls::min_lit_fraction);
  EXPECT_GE(lit_fraction_of_frame(c.profile(), Eye::left), 0.14);
}

TEST(CalibrationControls, AStartBelowTheThresholdMayOnlyGetBrighter) {
  Profile dim = load_profile("hmz-t1");
  dim.correction.prescription_diopters = -7.0;
  CalibrationControls c(dim, TestPattern::white);
  EXPECT_LT(c.lit_fraction(), CalibrationControls::min_lit_fraction);
  EXPECT_FALSE(c.apply(key(U'd')).profile_changed);
  EXPECT_TRUE(c.apply(key(U'D')).profile_changed);
  EXPECT_EQ(c.profile().correction.prescription_diopters, -6.75);
}

TEST(CalibrationControls, AChangeTheGeometryCannotShowIsRefused) {
  // Closer than ~120 mm no screen fits both eyes' field of view on hmz-t1 (the screen converges
  // half the IPD inwards): such a profile cannot even be mapped, and a key that would go there is
  // refused with that reason.
  Profile p = load_profile("hmz-t1");
  p.correction.prescription_diopters = -8.5;
  EXPECT_THROW(make_eye_mapping(p, Eye::left, 16.0 / 9.0), ProfileError);
  p.correction.prescription_diopters = -8.25;
  CalibrationControls c(p, TestPattern::grid);
  const CalibrationStep step = c.apply(key(U'd'));
  EXPECT_FALSE(step.profile_changed);
  EXPECT_NE(step.message.find("no screen fits"), std::string::npos) << step.message;
  EXPECT_EQ(c.profile().correction.prescription_diopters, -8.25);
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
  // profile_to_toml keeps the name; `nelf calibrate --save` gives the file its own.
  EXPECT_EQ(saved.name, "hmz-t1");
}

TEST(CalibrationControls, SavedProfilesGetTheirOwnName) {
  EXPECT_EQ(calibrated_profile_name("mine.toml"), "mine");
  EXPECT_EQ(calibrated_profile_name("/home/me/profiles/my-hmz.toml"), "my-hmz");
  // Never a built-in's name: the file would pass for the profile it started from.
  EXPECT_EQ(calibrated_profile_name("/tmp/hmz-t1.toml"), "hmz-t1-calibrated");
  EXPECT_EQ(calibrated_profile_name("hmz-t1-stock.toml"), "hmz-t1-stock-calibrated");
}

}  // namespace
}  // namespace nelf
