// `nelf calibrate --pattern P --output FILE`: the packed pattern frame written headless, through
// the same compositor as `nelf convert`, and every bad argument ending in one line, a non-zero
// status and no file.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "optics/profile.hpp"
#include "support/image_files.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::files_in;
using test::read_back;
using test::run_nelf;
using test::q;
using test::TempDir;

float luma(const test::ReadBack& img, int x, int y) {
  return (img.at(x, y, 0) + img.at(x, y, 1) + img.at(x, y, 2)) / 3.f;
}

long lit_pixels(const test::ReadBack& img, int y0, int y1) {
  long n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < img.width; ++x) n += luma(img, x, y) > 0.02f;
  return n;
}

// Lengths of the runs of bright and dark pixels down column x between rows y0 and y1.
std::vector<int> runs_down(const test::ReadBack& img, int x, int y0, int y1) {
  std::vector<int> runs;
  bool bright = luma(img, x, y0) > 0.5f;
  int length = 0;
  for (int y = y0; y < y1; ++y) {
    const bool b = luma(img, x, y) > 0.5f;
    if (b == bright) {
      ++length;
    } else {
      runs.push_back(length);
      bright = b;
      length = 1;
    }
  }
  return runs;
}

TEST(CalibrateCli, EveryPatternIsAFramePackedImage) {
  TempDir dir;
  for (const std::string pattern : {"stripes", "grid", "snellen", "white"}) {
    const auto out = dir / (pattern + ".png");
    const auto r = run_nelf("calibrate --pattern " + pattern + " --output " + q(out));
    ASSERT_EQ(r.status, 0) << pattern << ": " << r.err;
    EXPECT_EQ(r.err, "");
    const auto img = read_back(out);
    ASSERT_EQ(img.width, 1280) << pattern;
    ASSERT_EQ(img.height, 1470) << pattern;  // hdmi-fp-720p60: 720 + 30 gap rows + 720
    EXPECT_EQ(lit_pixels(img, 720, 750), 0) << pattern << ": the gap rows must be black";
    EXPECT_GT(lit_pixels(img, 0, 720), 1280 * 720 / 50) << pattern << ": left eye";
    EXPECT_GT(lit_pixels(img, 750, 1470), 1280 * 720 / 50) << pattern << ": right eye";
  }
}

TEST(CalibrateCli, StripesArePeriodicOnThePanel) {
  // On the stock device the view fills the panel: 1920 view pixels on 1280 panel pixels, stripes
  // of 5 view pixels (three display pixels, rounded), so 3.33 panel pixels per stripe.
  TempDir dir;
  const auto out = dir / "stripes.png";
  const auto r = run_nelf("calibrate --profile hmz-t1-stock --pattern stripes --output " + q(out));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto img = read_back(out);
  for (const int top : {0, 750}) {  // each eye
    // Top half of the view: horizontal stripes, so runs down a column.
    auto runs = runs_down(img, 640, top + 10, top + 350);
    ASSERT_GE(runs.size(), 90u) << top;
    runs.erase(runs.begin());  // the first run is cut by the window
    for (int run : runs) {
      EXPECT_GE(run, 3) << top;
      EXPECT_LE(run, 4) << top;
    }
    // Bottom half: vertical stripes, so a column there is constant.
    EXPECT_EQ(runs_down(img, 640, top + 370, top + 710).size(), 0u) << top;
  }
  // Through the lens array (hmz-t1) each elemental image shows the stripes too: runs of about three
  // display pixels inside every lenslet's image along a column of the left eye.
  const auto lf = dir / "lf.png";
  ASSERT_EQ(run_nelf("calibrate --pattern stripes --output " + q(lf)).status, 0);
  const auto lf_img = read_back(lf);
  const auto lf_runs = runs_down(lf_img, 600, 0, 720);
  const long regular = std::count_if(lf_runs.begin(), lf_runs.end(), [](int n) { return n >= 2 && n <= 4; });
  EXPECT_GT(regular, 60) << "runs: " << lf_runs.size();
}

TEST(CalibrateCli, ProfileAndSignalOptions) {
  TempDir dir;
  const auto out = dir / "grid.png";
  const auto r = run_nelf("calibrate --pattern grid --signal sbs --output " + q(out));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto img = read_back(out);
  EXPECT_EQ(img.width, 2560);
  EXPECT_EQ(img.height, 720);
}

TEST(CalibrateCli, DefectsWritesThePackedFlatFieldWithTheKnownDefectsRinged) {
  // --defects --output FILE: the field on every panel pixel (no lens mapping), a ring 2 px around
  // each defect of the profile's map (whole: dead, dotted: stuck), the defect pixels themselves
  // and everything else the field, the gap rows black.
  TempDir dir;
  Profile profile = load_profile("hmz-t1");
  profile.correction.defect_map = "panel.defects";
  test::write_file(dir / "panel.defects", "left 100 100 dead\nright 200 50 stuck 255 255 255\n");
  test::write_file(dir / "mine.toml", profile_to_toml(profile));
  const auto out = dir / "red.png";
  const auto r = run_nelf("calibrate --defects --field red --profile " + q(dir / "mine.toml") + " --output " + q(out));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const auto img = read_back(out);
  ASSERT_EQ(img.width, 1280);
  ASSERT_EQ(img.height, 1470);
  const auto is = [&](int x, int y, float red, float green, float blue) {
    return img.at(x, y, 0) == red && img.at(x, y, 1) == green && img.at(x, y, 2) == blue;
  };
  long left_rings = 0, right_rings = 0, other = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      if (y >= 720 && y < 750) {
        other += !is(x, y, 0, 0, 0);
      } else if (is(x, y, 0, 1, 1)) {
        (y < 720 ? left_rings : right_rings) += 1;
      } else {
        other += !is(x, y, 1, 0, 0);
      }
    }
  EXPECT_EQ(other, 0);
  EXPECT_EQ(left_rings, 16);  // the 5x5 square's outline
  EXPECT_EQ(right_rings, 8);  // every other pixel of it
  EXPECT_TRUE(is(100, 100, 1, 0, 0));
  EXPECT_TRUE(is(102, 100, 0, 1, 1));
  EXPECT_TRUE(is(200, 750 + 50, 1, 0, 0));
  EXPECT_TRUE(is(202, 750 + 52, 0, 1, 1));
  // The default field is black.
  const auto black = dir / "black.png";
  ASSERT_EQ(run_nelf("calibrate --defects --output " + q(black)).status, 0);
  EXPECT_EQ(lit_pixels(read_back(black), 0, 1470), 0);
}

TEST(CalibrateCli, BadArgumentsSayWhatAndWriteNothing) {
  TempDir dir;
  const std::string out = q(dir / "p.png");
  struct Case {
    std::string args;
    int status;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"--pattern checkers --output " + out, 2,
       "nelf: unknown pattern 'checkers' (use stripes, grid, snellen, white)\n"},
      {"--output " + out, 2,
       "nelf: --output " + (dir / "p.png").string() +
           " is an image file: give the pattern to write with --pattern stripes|grid|snellen|white\n"},
      {"--pattern grid --output " + q(dir / "missing" / "p.png"), 1, "does not exist"},
      {"--pattern grid --output " + q(dir / "p.bmpx"), 1, "p.bmpx"},
      {"--pattern grid --profile nosuch --output " + out, 2, "unknown profile 'nosuch'"},
      {"--pattern snellen --profile hmz-t1-stock --output " + out, 2,
       "nelf: pattern snellen: the Snellen chart needs the virtual screen's size"},
      {"--pattern grid --save " + q(dir / "x.toml") + " --output " + out, 2,
       "nelf: --save keeps what the keys adjusted and needs a window"},
      {"--pattern grid --fsaa 3 --output " + out, 2, "fsaa"},
      {"--pattern grid --gpu 0", 2, "a live calibration renders on its display's GPU"},
      {"--field white --output " + out, 2, "nelf: --field white is the flat field of --defects: add --defects"},
      {"--defects --pattern grid --output " + out, 2, "nelf: --defects shows flat fields, not --pattern grid"},
      {"--defects --fsaa 4 --output " + out, 2, "nelf: --fsaa antialiases the lens mapping"},
      {"--defects --field pink --output " + out, 2, "pink not in {black,white,red,green,blue}"},
      {"--defects --save " + q(dir / "x.toml") + " --output " + out, 2,
       "nelf: --save keeps what the keys marked and needs a window"},
      {"--defects --save " + q(dir / "x.txt"), 2, "a profile is a .toml file"},
  };
  for (const auto& c : cases) {
    const auto r = run_nelf("calibrate " + c.args);
    EXPECT_EQ(r.status, c.status) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.args << ": " << r.err;
    EXPECT_EQ(files_in(dir.path()), std::vector<std::string>{}) << c.args;
  }
}

TEST(CalibrateCli, DefectsKeepsAMapTheProfileDoesNotName) {
  // mine.defects beside --save mine.toml, not named by the profile: refused before any window
  // opens, the file left as it was.
  TempDir dir;
  test::write_file(dir / "mine.defects", "left 1 1 dead\n");
  const auto r = run_nelf("calibrate --defects --output offscreen --save " + q(dir / "mine.toml"));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err, "nelf: --save " + (dir / "mine.toml").string() + ": " + (dir / "mine.defects").string() +
                       " exists and the profile names no defect map; to continue it, set correction.defect_map = "
                       "\"mine.defects\" in the profile, else move it away\n");
  EXPECT_EQ(test::read_file(dir / "mine.defects"), "left 1 1 dead\n");
  EXPECT_EQ(files_in(dir.path()), std::vector<std::string>{"mine.defects"});
}

TEST(CalibrateCli, UnwritableOutputLeavesNoFile) {
  // /proc takes no new files, not even from root: the write itself fails after the checks pass.
  const auto r = run_nelf("calibrate --pattern grid --output /proc/nelf-calibrate-test.png");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err.rfind("nelf: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists("/proc/nelf-calibrate-test.png"));
}

TEST(CalibrateCli, ExistingOutputNeedsOverwrite) {
  TempDir dir;
  const auto out = dir / "p.png";
  test::write_file(out, "keep me");
  auto r = run_nelf("calibrate --pattern white --output " + q(out));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("pass -y to overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(test::read_file(out), "keep me");
  r = run_nelf("calibrate --pattern white -y --output " + q(out));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_back(out).height, 1470);
}

}  // namespace
}  // namespace nelf
