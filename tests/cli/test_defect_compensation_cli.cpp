// `nelf convert` with a profile whose defect map names dead and stuck pixels: the defects are hidden
// by default, changing only the pixels of their bundles; --no-defect-compensation gives what a
// profile without the map gives.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <utility>

#include "optics/defect_compensation.hpp"
#include "optics/defect_map.hpp"
#include "optics/mapping.hpp"
#include "optics/profile.hpp"
#include "support/image_files.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::q;
using test::read_back;
using test::run_nelf;
using test::TempDir;

// The small 160×90 test panel, with the defect map or without.
std::string small_profile_text(bool with_map) {
  std::string text = R"(name = "small"
[display]
resolution = [160, 90]
pixel_pitch_mm = 0.096
[lens_array]
pitch_mm = 1.0
focal_length_mm = 3.3
[viewing]
eye_relief_mm = 25.0
virtual_image_mm = 1000.0
)";
  if (with_map) text += "[correction]\ndefect_map = \"panel.defects\"\n";
  return text;
}

// The pixels of the sbs frame (the left eye at x 0..159, the right at 160..319) that take a share.
std::set<std::pair<int, int>> share_pixels(const Profile& profile, double aspect) {
  std::set<std::pair<int, int>> pixels;
  for (Eye eye : {Eye::left, Eye::right}) {
    const EyeDefectPlan plan =
        plan_defect_compensation(make_eye_mapping(profile, eye, aspect), *profile.correction.defects);
    const int x0 = eye == Eye::left ? 0 : profile.display.resolution[0];
    for (const auto& c : plan.corrections)
      for (const auto& s : c.shares) pixels.insert({x0 + s.x, s.y});
  }
  return pixels;
}

std::set<std::pair<int, int>> differing(const test::ReadBack& a, const test::ReadBack& b) {
  std::set<std::pair<int, int>> pixels;
  EXPECT_EQ(a.pixels.size(), b.pixels.size());
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int c = 0; c < 3; ++c)
        if (a.at(x, y, c) != b.at(x, y, c)) pixels.insert({x, y});
  return pixels;
}

TEST(DefectCompensationCli, ConvertHidesTheDefectsOnlyAtTheirBundles) {
  TempDir dir;
  test::write_file(dir / "panel.defects",
                   "# a few of each kind in the lit middle of both panels\n"
                   "left 80 45 dead\nleft 70 40 stuck 255 255 255\nleft 90 50 stuck 255 0 0\n"
                   "right 81 44 dead\nright 60 50 stuck 255 255 255\n");
  test::write_file(dir / "mapped.toml", small_profile_text(true));
  test::write_file(dir / "plain.toml", small_profile_text(false));
  const std::string input = "synthetic:duration=0.125,size=320x180 ";
  const std::string tail = " --signal sbs --quiet --frames 2";
  const auto on = run_nelf("convert " + input + q(dir / "on_%02d.png") + tail + " --profile " + q(dir / "mapped.toml"));
  ASSERT_EQ(on.status, 0) << on.err;
  EXPECT_NE(on.err.find("nelf: hiding "), std::string::npos) << on.err;
  EXPECT_NE(on.err.find("defects of the profile's defect map"), std::string::npos) << on.err;
  const auto off = run_nelf("convert " + input + q(dir / "off_%02d.png") + tail + " --profile " +
                            q(dir / "mapped.toml") + " --no-defect-compensation");
  ASSERT_EQ(off.status, 0) << off.err;
  EXPECT_EQ(off.err.find("nelf: hiding"), std::string::npos) << off.err;
  const auto plain =
      run_nelf("convert " + input + q(dir / "plain_%02d.png") + tail + " --profile " + q(dir / "plain.toml"));
  ASSERT_EQ(plain.status, 0) << plain.err;

  const Profile profile = load_profile((dir / "mapped.toml").string());
  const auto shares = share_pixels(profile, 16.0 / 9.0);
  ASSERT_FALSE(shares.empty());
  for (const char* frame : {"01", "02"}) {
    SCOPED_TRACE(frame);
    const auto hidden = read_back(dir / (std::string("on_") + frame + ".png"));
    const auto shown = read_back(dir / (std::string("off_") + frame + ".png"));
    const auto changed = differing(hidden, shown);
    EXPECT_FALSE(changed.empty());
    for (const auto& p : changed) EXPECT_TRUE(shares.count(p)) << p.first << "," << p.second;
    EXPECT_TRUE(differing(shown, read_back(dir / (std::string("plain_") + frame + ".png"))).empty());
  }
}

TEST(DefectCompensationCli, CalibratesPatternImageIsHiddenToo) {
  TempDir dir;
  test::write_file(dir / "panel.defects",
                   "left 80 45 dead\nleft 70 40 stuck 255 255 255\nleft 90 50 stuck 255 0 0\n"
                   "right 81 44 dead\nright 60 50 stuck 255 255 255\n");
  test::write_file(dir / "mapped.toml", small_profile_text(true));
  const std::string base = "calibrate --pattern grid --signal sbs --profile " + q(dir / "mapped.toml") + " --output ";
  const auto on = run_nelf(base + q(dir / "on.png"));
  ASSERT_EQ(on.status, 0) << on.err;
  EXPECT_NE(on.err.find("nelf: hiding "), std::string::npos) << on.err;
  const auto off = run_nelf(base + q(dir / "off.png") + " --no-defect-compensation");
  ASSERT_EQ(off.status, 0) << off.err;
  EXPECT_FALSE(differing(read_back(dir / "on.png"), read_back(dir / "off.png")).empty());
}

}  // namespace
}  // namespace nelf
