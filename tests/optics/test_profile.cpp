#include <gtest/gtest.h>

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "optics/mapping.hpp"
#include "optics/profile.hpp"

namespace nelf {
namespace {
// This file's own names: its suite is compiled as one unit (tests/CMakeLists.txt).
namespace test_profile {

const char* minimal_lens_profile = R"(
name = "test"
[display]
resolution = [1280, 720]
pixel_pitch_mm = 0.012
[lens_array]
pitch_mm = 1.0
focal_length_mm = 3.3
[viewing]
eye_relief_mm = 25.0
virtual_image_mm = 1000.0
)";

std::string error_of(const std::string& text) {
  try {
    parse_profile(text, "dev.toml");
  } catch (const ProfileError& e) {
    return e.what();
  }
  return "";
}

TEST(Profile, BuiltinHmzT1HasDesignValues) {
  const Profile p = load_profile("hmz-t1");
  EXPECT_EQ(p.name, "hmz-t1");
  EXPECT_EQ(p.display.resolution[0], 1280);
  EXPECT_EQ(p.display.resolution[1], 720);
  EXPECT_DOUBLE_EQ(p.display.pixel_pitch_mm.x, 0.012);
  ASSERT_TRUE(p.lens_array);
  EXPECT_DOUBLE_EQ(p.lens_array->pitch_mm, 1.0);
  EXPECT_DOUBLE_EQ(p.lens_array->focal_length_mm, 3.3);
  EXPECT_FALSE(p.lens_array->gap_mm);
  EXPECT_DOUBLE_EQ(p.viewing.eye_relief_mm, 25.0);
  EXPECT_DOUBLE_EQ(p.viewing.virtual_image_mm, 1000.0);
  EXPECT_EQ(p.signal, "hdmi-fp-720p60");
}

TEST(Profile, BuiltinStockHasNoLensArray) {
  const Profile p = load_profile("hmz-t1-stock");
  EXPECT_FALSE(p.lens_array);
  EXPECT_FALSE(p.screen.converge);
}

TEST(Profile, BuiltinListNamesEach) {
  const auto list = builtin_profiles();
  ASSERT_EQ(list.size(), 4u);
  for (const auto& b : list) EXPECT_FALSE(b.description.empty()) << b.name;
}

TEST(Profile, TheFinerDisplaysOfTheDepthIssueLoad) {
  // The paper's LVT film prototype and a published 2160 x 2160 integral-imaging testbed (issue #15):
  // panels larger than any frame-packed mode, so their output is side by side.
  const Profile lvt = load_profile("lvt-prototype");
  EXPECT_EQ(lvt.display.resolution, (std::array<int, 2>{4500, 4500}));
  EXPECT_DOUBLE_EQ(lvt.display.pixel_pitch_mm.x, 0.00833);
  ASSERT_TRUE(lvt.lens_array);
  EXPECT_DOUBLE_EQ(lvt.lens_array->focal_length_mm, 3.3);
  EXPECT_DOUBLE_EQ(lvt.viewing.eye_relief_mm, 25.0);
  EXPECT_EQ(lvt.signal, "sbs");
  const Profile ii = load_profile("ii-2160-testbed");
  EXPECT_EQ(ii.display.resolution, (std::array<int, 2>{2160, 2160}));
  ASSERT_TRUE(ii.lens_array);
  EXPECT_DOUBLE_EQ(ii.lens_array->pitch_mm, 1.2);
  EXPECT_DOUBLE_EQ(lens_gap_mm(ii), 6.316);
  EXPECT_DOUBLE_EQ(ii.viewing.eye_relief_mm, 20.0);
  EXPECT_EQ(ii.signal, "sbs");
}

TEST(Profile, DefaultsForOptionalTables) {
  const Profile p = parse_profile(minimal_lens_profile, "dev.toml");
  EXPECT_DOUBLE_EQ(p.viewing.pupil_mm, 4.0);
  EXPECT_DOUBLE_EQ(p.viewing.ipd_mm, 63.0);
  EXPECT_DOUBLE_EQ(p.screen.distance_mm, 0.0);
  EXPECT_DOUBLE_EQ(p.screen.width_mm, 0.0);
  EXPECT_TRUE(p.screen.converge);
  EXPECT_EQ(p.signal, "hdmi-fp-720p60");
  EXPECT_DOUBLE_EQ(p.calibration[1].pitch_scale, 1.0);
  EXPECT_DOUBLE_EQ(p.magnifier_comparison.eye_box_mm, 10.0);
  EXPECT_DOUBLE_EQ(p.magnifier_comparison.f_number, 1.0);
}

TEST(Profile, SizeInsteadOfPitch) {
  std::string text = minimal_lens_profile;
  text.replace(text.find("pixel_pitch_mm = 0.012"), 22, "size_mm = [15.36, 8.64]");
  const Profile p = parse_profile(text, "dev.toml");
  EXPECT_NEAR(p.display.pixel_pitch_mm.x, 0.012, 1e-12);
  EXPECT_NEAR(p.display.pixel_pitch_mm.y, 0.012, 1e-12);
}

TEST(Profile, RoundTripsThroughToml) {
  Profile p = load_profile("hmz-t1");
  p.calibration[0].shift_px = {1.5, -2};
  p.calibration[1].rotation_deg = 0.25;
  p.correction.prescription_diopters = -2;
  const Profile q = parse_profile(profile_to_toml(p), "saved.toml");
  EXPECT_EQ(q.calibration[0].shift_px, p.calibration[0].shift_px);
  EXPECT_DOUBLE_EQ(q.calibration[1].rotation_deg, 0.25);
  EXPECT_DOUBLE_EQ(q.correction.prescription_diopters, -2);
  EXPECT_EQ(q.name, p.name);
  EXPECT_EQ(q.description, p.description);
}

TEST(Profile, RoundTripsNamesWithQuotesAndBackslashes) {
  // A profile named by its user (nelf calibrate --save) may hold any text; it must load again.
  Profile p = load_profile("hmz-t1");
  p.name = R"(my "tuned" HMZ \ v2)";
  p.description = "line one\nline \"two\"\ttab";
  const Profile q = parse_profile(profile_to_toml(p), "saved.toml");
  EXPECT_EQ(q.name, p.name);
  EXPECT_EQ(q.description, p.description);
}

TEST(ProfileErrors, SyntaxErrorNamesFileAndLine) {
  const auto e = error_of("name = \"x\"\n[display\nresolution = [1,2]\n");
  EXPECT_NE(e.find("dev.toml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("syntax"), std::string::npos) << e;
}

TEST(ProfileErrors, UnknownKeySuggestsNearest) {
  std::string text = minimal_lens_profile;
  text.replace(text.find("focal_length_mm"), 15, "focal_lenght_mm");
  const auto e = error_of(text);
  EXPECT_NE(e.find("lens_array.focal_lenght_mm"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean lens_array.focal_length_mm"), std::string::npos) << e;
  EXPECT_NE(e.find("dev.toml:8"), std::string::npos) << e;
}

TEST(ProfileErrors, WrongType) {
  std::string text = minimal_lens_profile;
  text.replace(text.find("pitch_mm = 1.0"), 14, "pitch_mm = \"wide\"");
  const auto e = error_of(text);
  EXPECT_NE(e.find("lens_array.pitch_mm must be a number, got \"wide\""), std::string::npos) << e;
}

TEST(ProfileErrors, NonPositiveFocalLength) {
  std::string text = minimal_lens_profile;
  text.replace(text.find("focal_length_mm = 3.3"), 21, "focal_length_mm = -3");
  const auto e = error_of(text);
  EXPECT_NE(e.find("lens_array.focal_length_mm must be > 0, got -3"), std::string::npos) << e;
  EXPECT_NE(e.find("dev.toml"), std::string::npos) << e;
}

TEST(ProfileErrors, NonPositivePitchAndResolution) {
  std::string text = minimal_lens_profile;
  text.replace(text.find("pitch_mm = 1.0"), 14, "pitch_mm = 0");
  EXPECT_NE(error_of(text).find("lens_array.pitch_mm must be > 0, got 0"), std::string::npos);
  text = minimal_lens_profile;
  text.replace(text.find("[1280, 720]"), 11, "[0, 720]");
  EXPECT_NE(error_of(text).find("display.resolution must be between 1 and 16384"), std::string::npos);
  text = minimal_lens_profile;
  text.replace(text.find("pixel_pitch_mm = 0.012"), 22, "pixel_pitch_mm = -0.01");
  EXPECT_NE(error_of(text).find("display.pixel_pitch_mm must be > 0, got -0.01"), std::string::npos);
}

TEST(ProfileErrors, VirtualImageTooClose) {
  std::string text = minimal_lens_profile;
  text.replace(text.find("virtual_image_mm = 1000.0"), 25, "virtual_image_mm = 28");
  const auto e = error_of(text);
  EXPECT_NE(e.find("viewing.virtual_image_mm must be > viewing.eye_relief_mm + lens_array.focal_length_mm"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("got 28"), std::string::npos) << e;
}

TEST(ProfileErrors, LensWiderThanDisplay) {
  std::string text = minimal_lens_profile;
  text.replace(text.find("pitch_mm = 1.0"), 14, "pitch_mm = 9");
  const auto e = error_of(text);
  EXPECT_NE(e.find("lens_array.pitch_mm must be <= the display's smaller side"), std::string::npos) << e;
}

// --- bounds on every length and derived figure (docs/profiles.md "Limits") -------------------------

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("test profile has no '" + from + "'");
  return text.replace(at, from.size(), to);
}

// One line naming the file and the key, and each expected part of the rule.
void expect_refused(const std::string& text, const std::string& key, const std::vector<std::string>& parts = {}) {
  SCOPED_TRACE(text);
  const std::string e = error_of(text);
  ASSERT_FALSE(e.empty()) << "accepted";
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  EXPECT_EQ(e.rfind("dev.toml", 0), 0u) << e;
  EXPECT_NE(e.find(key), std::string::npos) << e;
  for (const auto& part : parts) EXPECT_NE(e.find(part), std::string::npos) << e;
}

TEST(ProfileBounds, HugePixelPitchIsRefusedByThePanelSize) {
  // 16384 mm pixels made a 21 km panel with millions of 1 mm lenses (convert hung); 1e9 overflowed
  // the lens count.
  for (const char* pitch : {"16384", "1e9", "1e300", "0.8"}) {
    expect_refused(replaced(minimal_lens_profile, "pixel_pitch_mm = 0.012", std::string("pixel_pitch_mm = ") + pitch),
                   "display.pixel_pitch_mm", {"at most 1000 mm a side"});
  }
  expect_refused(replaced(minimal_lens_profile, "pixel_pitch_mm = 0.012", "size_mm = [15.36, 1e12]"), "display.size_mm",
                 {"at most 1000 mm a side"});
  // 0.78 mm pixels make a 998 x 562 mm panel: large, but a panel.
  EXPECT_EQ(error_of(replaced(replaced(minimal_lens_profile, "pixel_pitch_mm = 0.012", "pixel_pitch_mm = 0.78"),
                              "pitch_mm = 1.0", "pitch_mm = 2.0")),
            "");
}

TEST(ProfileBounds, TinyPixelPitchIsRefused) {
  for (const char* pitch : {"1e-5", "1e-300", "5e-324"})
    expect_refused(replaced(minimal_lens_profile, "pixel_pitch_mm = 0.012", std::string("pixel_pitch_mm = ") + pitch),
                   "display.pixel_pitch_mm", {"at least 0.0001 mm"});
}

TEST(ProfileBounds, LensesMustCoverAtLeastTwoPixels) {
  // 0.01 mm lenses on 12 µm pixels: 0.94 px per elemental image, 1360 lenses across 1280 px.
  expect_refused(replaced(minimal_lens_profile, "pitch_mm = 1.0", "pitch_mm = 0.01"), "lens_array.pitch_mm",
                 {"at least 2 px", "horizontal", "at most 640"});
  // Two pixels is enough: 0.0212 mm lenses give 2.0 px (d_e + d_l)/d_e · w_l / p.
  EXPECT_EQ(error_of(replaced(minimal_lens_profile, "pitch_mm = 1.0", "pitch_mm = 0.0215")), "");
}

TEST(ProfileBounds, NonFiniteAndExtremeValuesAreRefused) {
  struct Case {
    const char *from, *to, *key;
  };
  const Case cases[] = {
      {"pixel_pitch_mm = 0.012", "pixel_pitch_mm = nan", "display.pixel_pitch_mm"},
      {"pixel_pitch_mm = 0.012", "pixel_pitch_mm = inf", "display.pixel_pitch_mm"},
      {"pixel_pitch_mm = 0.012", "pixel_pitch_mm = 0", "display.pixel_pitch_mm"},
      {"pixel_pitch_mm = 0.012", "size_mm = [nan, 8.64]", "display.size_mm"},
      {"pixel_pitch_mm = 0.012", "size_mm = [inf, 8.64]", "display.size_mm"},
      {"pitch_mm = 1.0", "pitch_mm = -inf", "lens_array.pitch_mm"},
      {"focal_length_mm = 3.3", "focal_length_mm = 1e-9", "lens_array.focal_length_mm"},
      {"focal_length_mm = 3.3", "focal_length_mm = 1e300", "lens_array.focal_length_mm"},
      {"focal_length_mm = 3.3", "focal_length_mm = 3.3\ngap_mm = 1e300", "lens_array.gap_mm"},
      {"focal_length_mm = 3.3", "focal_length_mm = 3.3\ngap_mm = -1", "lens_array.gap_mm"},
      {"focal_length_mm = 3.3", "focal_length_mm = 3.3\noffset_mm = [nan, 0]", "lens_array.offset_mm"},
      {"focal_length_mm = 3.3", "focal_length_mm = 3.3\noffset_mm = [1e9, 0]", "lens_array.offset_mm"},
      {"focal_length_mm = 3.3", "focal_length_mm = 3.3\nrotation_deg = 1e300", "lens_array.rotation_deg"},
      {"eye_relief_mm = 25.0", "eye_relief_mm = 1e-300", "viewing.eye_relief_mm"},
      {"eye_relief_mm = 25.0", "eye_relief_mm = nan", "viewing.eye_relief_mm"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = 1e300", "viewing.virtual_image_mm"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = inf", "viewing.virtual_image_mm"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = 1000.0\npupil_mm = 1e300", "viewing.pupil_mm"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = 1000.0\npupil_mm = 40", "viewing.pupil_mm"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = 1000.0\nipd_mm = -63", "viewing.ipd_mm"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = 1000.0\n[screen]\nwidth_mm = 1e300", "screen.width_mm"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = 1000.0\n[screen]\ndistance_mm = 1e300", "screen.distance_mm"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = 1000.0\n[calibration.left]\npitch_scale = 1e-300",
       "calibration.left.pitch_scale"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = 1000.0\n[calibration.right]\nshift_px = [0, 1e300]",
       "calibration.right.shift_px"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = 1000.0\n[calibration.right]\nshift_px = [inf, 0]",
       "calibration.right.shift_px"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = 1000.0\n[magnifier_comparison]\nf_number = 1e200",
       "magnifier_comparison.f_number"},
  };
  for (const auto& c : cases) expect_refused(replaced(minimal_lens_profile, c.from, c.to), c.key);
}

TEST(ProfileBounds, MagnifierFiguresAreBoundedToo) {
  const std::string loupe = R"(
[display]
resolution = [1600, 1200]
pixel_pitch_mm = 0.01
[magnifier]
width_mm = 20.0
focal_length_mm = 40.0
[viewing]
eye_relief_mm = 20.0
virtual_image_mm = 2000.0
)";
  EXPECT_EQ(error_of(loupe), "");
  expect_refused(replaced(loupe, "eye_relief_mm = 20.0", "eye_relief_mm = 1e-300"), "viewing.eye_relief_mm");
  expect_refused(replaced(loupe, "width_mm = 20.0", "width_mm = 1e300"), "magnifier.width_mm");
}

TEST(ProfileBounds, StrongPrescriptionMustLeaveTheScreenBeyondTheDisplay) {
  // Far point 1000/20 = 50 mm, behind a display at 60 + 3.3 mm.
  const std::string far_relief = replaced(replaced(minimal_lens_profile, "eye_relief_mm = 25.0", "eye_relief_mm = 60"),
                                          "virtual_image_mm = 1000.0",
                                          "virtual_image_mm = 1000.0\n[correction]\n"
                                          "prescription_diopters = -20");
  expect_refused(far_relief, "correction.prescription_diopters", {"far point at 50 mm", "beyond the display"});
}

TEST(ProfileBounds, EveryFigureOfAnAcceptedProfileFitsItsType) {
  // The extremes the rules allow still give finite figures and counts that fit an int.
  const std::string extreme = R"(
[display]
resolution = [16384, 16384]
pixel_pitch_mm = 0.061
[lens_array]
pitch_mm = 0.25
focal_length_mm = 0.5
[viewing]
eye_relief_mm = 0.001
virtual_image_mm = 1000000
pupil_mm = 1
)";
  EXPECT_EQ(error_of(extreme), "");
}

TEST(ProfileErrors, MissingRequiredTable) {
  const auto e = error_of("name = \"x\"\n[display]\nresolution = [10, 10]\npixel_pitch_mm = 0.1\n");
  EXPECT_NE(e.find("[viewing] is required"), std::string::npos) << e;
}

TEST(ProfileErrors, UnknownBuiltinListsBuiltins) {
  try {
    load_profile("hmz-t2");
    FAIL() << "expected an error";
  } catch (const ProfileError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("unknown profile 'hmz-t2'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("hmz-t1, hmz-t1-stock"), std::string::npos) << msg;
  }
}

TEST(ProfileErrors, MissingFile) {
  try {
    load_profile("/nonexistent/dev.toml");
    FAIL() << "expected an error";
  } catch (const ProfileError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dev.toml: cannot read profile"), std::string::npos);
  }
}

TEST(ProfileErrors, ArraysAreShownOnOneLineAndCutShort) {
  std::string text = minimal_lens_profile;
  text.replace(text.find("resolution = [1280, 720]"), 24, "resolution = [\n  1280,\n  720,\n  3,\n]");
  auto e = error_of(text);
  EXPECT_NE(e.find("got [1280, 720, 3]"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  std::string many = "resolution = [";
  for (int i = 0; i < 1000; ++i) many += std::to_string(i) + ",\n";
  text = minimal_lens_profile;
  text.replace(text.find("resolution = [1280, 720]"), 24, many + "]");
  e = error_of(text);
  EXPECT_NE(e.find("got [0, 1, 2, 3, 4, 5, 6, 7, ... (1000 values)]"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

}  // namespace test_profile
}  // namespace
}  // namespace nelf
