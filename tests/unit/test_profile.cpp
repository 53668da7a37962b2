#include <gtest/gtest.h>

#include "compositor/profile.hpp"

namespace nelf {
namespace {

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

TEST(Profile, BuiltinListNamesBoth) {
  const auto list = builtin_profiles();
  ASSERT_EQ(list.size(), 2u);
  for (const auto& b : list) EXPECT_FALSE(b.description.empty()) << b.name;
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

}  // namespace
}  // namespace nelf
