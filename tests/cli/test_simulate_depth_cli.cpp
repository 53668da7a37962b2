// `nelf simulate` on the scene whose depth is known (issue #15): the eye looking through the
// hmz-t1 at synthetic:scene=planes, judged against the real scene, with and without depth.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "support/test_support.hpp"

namespace nelf::test {
namespace {

struct PlanesRun {
  std::string depth_used;
  std::map<std::string, double> psnr_db;              // per region
  std::map<std::string, double> best_focus_diopters;  // per region, with --focus-sweep
};

PlanesRun simulate_planes(const TempDir& dir, const std::string& args) {
  const CommandResult r =
      run_nelf("simulate synthetic:scene=planes --profile hmz-t1 -o " + q(dir / "retina.png") + " --json " + args);
  EXPECT_EQ(r.status, 0) << r.err;
  PlanesRun run;
  if (r.status != 0) return run;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("reference"), "scene");  // auto: the source knows its scene
  run.depth_used = j.at("depth_used").get<std::string>();
  for (const auto& region : j.at("regions")) run.psnr_db[region.at("name")] = region.at("psnr_db").get<double>();
  if (j.contains("focus_sweep"))
    for (const auto& region : j.at("focus_sweep"))
      run.best_focus_diopters[region.at("name")] = region.at("best_focus_diopters").get<double>();
  return run;
}

TEST(SimulateDepthCli, TheNearPlaneIsSharperWhereTheEyeFocusesOnIt) {
  // Measured on hmz-t1 (docs/depth.md): near plane at 250 mm, eye focused there, 27.5 dB flat,
  // 32.5 dB with the exact depth, 32.3 dB estimated; the far plane at 1000 mm (the screen), eye
  // focused there, 32.2 dB flat and 32.5 dB with depth.
  TempDir dir;
  const PlanesRun flat = simulate_planes(dir, "--depth off --focus-mm 250");
  const PlanesRun exact = simulate_planes(dir, "--depth auto --focus-mm 250");
  const PlanesRun estimated = simulate_planes(dir, "--depth estimate --focus-mm 250");
  EXPECT_EQ(flat.depth_used, "none");
  EXPECT_EQ(exact.depth_used, "known");
  EXPECT_EQ(estimated.depth_used, "estimated");
  EXPECT_GT(exact.psnr_db.at("near"), flat.psnr_db.at("near") + 4.0);
  EXPECT_GT(estimated.psnr_db.at("near"), exact.psnr_db.at("near") - 1.0);
  const PlanesRun flat_far = simulate_planes(dir, "--depth off --focus-mm 1000");
  const PlanesRun exact_far = simulate_planes(dir, "--depth auto --focus-mm 1000");
  EXPECT_GT(exact_far.psnr_db.at("far"), flat_far.psnr_db.at("far") - 0.5);
}

TEST(SimulateDepthCli, FocusFollowsEachPlanesDepth) {
  // Sweeping the accommodation: with depth each plane is sharpest at its own depth (measured: near
  // 3.87 D for 4 D, far 0.85 D for 1 D); flat, both are sharpest at the screen (near 0.81 D).
  TempDir dir;
  const auto csv = dir / "focus.csv";
  const PlanesRun exact = simulate_planes(dir, "--depth auto --focus-sweep " + q(csv));
  EXPECT_NEAR(exact.best_focus_diopters.at("near"), 4.0, 0.25);
  EXPECT_NEAR(exact.best_focus_diopters.at("far"), 1.0, 0.25);
  const std::string table = read_file(csv);
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 1 + 2 * 19) << table;  // 2 regions × 19 accommodations
  EXPECT_TRUE(std::filesystem::exists(dir / "focus.png"));
  const PlanesRun flat = simulate_planes(dir, "--depth off --focus-sweep " + q(csv));
  EXPECT_NEAR(flat.best_focus_diopters.at("near"), 1.0, 0.3);
}

TEST(SimulateDepthCli, AStillHasNoSceneToCompareWith) {
  TempDir dir;
  const auto still = write_lavfi_still(dir, "still.png", "testsrc2=s=512x144");
  expect_clean_failure(dir, "simulate " + q(still) + " --layout sbs --reference scene -o " + q(dir / "retina.png"), 2,
                       "--reference scene needs an input that knows its depth");
}

TEST(SimulateDepthCli, ABlackPairCannotBeMatchedAndFallsBackToTheScreen) {
  // No texture, no disparity: the flat screen, said once, never garbage.
  TempDir dir;
  const auto still = write_lavfi_still(dir, "black.png", "color=black:s=512x144");
  const CommandResult r =
      run_nelf("simulate " + q(still) + " --layout sbs --depth estimate -o " + q(dir / "retina.png"));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("cannot be matched"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("none to be had: the flat screen"), std::string::npos) << r.out;
}

TEST(SimulateDepthCli, BadSyntheticOptions) {
  TempDir dir;
  const std::string out = " -o " + q(dir / "retina.png");
  expect_clean_failure(dir, "simulate synthetic:scene=cubes" + out, 2, "scene must be spheres or planes");
  expect_clean_failure(dir, "simulate synthetic:scene=planes,near=2000" + out, 2, "must be nearer than the far one");
}

}  // namespace
}  // namespace nelf::test
