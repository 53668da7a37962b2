// `--depth` on convert and play (issue #15), run as a user would: a synthetic scene composited with
// its exact depth, a stereo photo made by the ffmpeg CLI with its depth estimated, and the inputs
// whose depth cannot be had falling back to the flat screen, said once.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "support/test_support.hpp"

namespace nelf::test {
namespace {

// Raw 8-bit RGBA of `nelf convert IN - ARGS` on the small profile, both eyes side by side (320x90).
struct Converted {
  int status = -1;
  std::string frames, err;
};
Converted convert_raw(const TempDir& dir, const std::string& input, const std::string& args) {
  const CommandResult r = run_nelf("convert " + shell_quote(input) + " - --profile " + q(write_small_profile(dir)) +
                                   " --signal sbs " + args);
  return {r.status, r.out, r.err};
}

// Mean absolute difference of two equally long byte strings (0-255).
double mean_difference(const std::string& a, const std::string& b) {
  EXPECT_EQ(a.size(), b.size());
  double sum = 0;
  const std::size_t n = std::min(a.size(), b.size());
  for (std::size_t i = 0; i < n; ++i)
    sum += std::abs(static_cast<unsigned char>(a[i]) - static_cast<unsigned char>(b[i]));
  return n ? sum / static_cast<double>(n) : 0.0;
}

// The lines of `text` that contain `what`.
int count_lines_with(const std::string& text, const std::string& what) {
  int count = 0;
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    count += text.substr(start, end - start).find(what) != std::string::npos;
    start = end + 1;
  }
  return count;
}

// A side-by-side photo whose right view is the left shifted 24 px to the left: a textured scene
// (ffmpeg's testsrc2) uniformly in front of the screen, at about half its distance; or all black.
std::filesystem::path stereo_photo(const TempDir& dir, bool black) {
  return write_lavfi_still(dir, black ? "black.png" : "photo.png",
                           black ? "color=black:s=256x144" : "testsrc2=s=256x144",
                           "split[l][r];[r]crop=232:144:24:0,pad=256:144:0:0[s];[l][s]hstack");
}

TEST(DepthCli, ConvertCompositesASyntheticSceneWithItsDepth) {
  TempDir dir;
  const std::string clip = "synthetic:scene=planes,duration=0.25,size=320x180";
  const Converted flat = convert_raw(dir, clip, "--depth off");
  const Converted exact = convert_raw(dir, clip, "--depth auto");
  const Converted estimated = convert_raw(dir, clip, "--depth estimate");
  ASSERT_EQ(flat.status, 0) << flat.err;
  ASSERT_EQ(exact.status, 0) << exact.err;
  ASSERT_EQ(estimated.status, 0) << estimated.err;
  EXPECT_EQ(flat.frames.size(), 6u * 320 * 90 * 4);  // 0.25 s at 24 fps
  // The near plane moves in each elemental image; the estimate lands close to the exact depth.
  const double moved = mean_difference(flat.frames, exact.frames);
  EXPECT_GT(moved, 2.0);
  EXPECT_LT(mean_difference(exact.frames, estimated.frames), moved / 3);
  EXPECT_EQ(exact.err.find("--depth"), std::string::npos) << exact.err;  // nothing to say
}

TEST(DepthCli, ConvertEstimatesAStereoPhotosDepth) {
  TempDir dir;
  const auto photo = stereo_photo(dir, false);
  const Converted flat = convert_raw(dir, photo.string(), "--layout sbs --depth off");
  const Converted estimated = convert_raw(dir, photo.string(), "--layout sbs --depth auto");
  ASSERT_EQ(flat.status, 0) << flat.err;
  ASSERT_EQ(estimated.status, 0) << estimated.err;
  EXPECT_GT(mean_difference(flat.frames, estimated.frames), 1.0);
  EXPECT_EQ(estimated.err.find("--depth"), std::string::npos) << estimated.err;
}

TEST(DepthCli, APairThatCannotBeMatchedIsShownFlatAndSaidOnce) {
  TempDir dir;
  const auto photo = stereo_photo(dir, true);
  const Converted flat = convert_raw(dir, photo.string(), "--layout sbs --depth off");
  const Converted estimated = convert_raw(dir, photo.string(), "--layout sbs --depth estimate");
  ASSERT_EQ(estimated.status, 0) << estimated.err;
  EXPECT_EQ(estimated.frames, flat.frames);  // never garbage: the flat screen
  EXPECT_EQ(count_lines_with(estimated.err, "--depth"), 1) << estimated.err;
  EXPECT_NE(estimated.err.find("nelf: --depth estimate: a frame without depth"), std::string::npos) << estimated.err;
}

TEST(DepthCli, AStockDisplayCannotShowDepthAndSaysSoOnce) {
  TempDir dir;
  const CommandResult r = run_nelf(
      "convert synthetic:scene=planes,duration=0.25,size=64x36 - --profile hmz-t1-stock "
      "--signal left --depth auto");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(count_lines_with(r.err, "--depth"), 1) << r.err;
  EXPECT_NE(r.err.find("profile hmz-t1-stock has no lens array"), std::string::npos) << r.err;
}

TEST(DepthCli, AnUnknownModeIsRefused) {
  TempDir dir;
  for (const char* command : {"convert synthetic: out.mkv", "play synthetic: --output offscreen"})
    expect_clean_failure(dir, std::string(command) + " --depth near", 2,
                         "--depth must be one of off, auto, estimate, got 'near'");
}

TEST(DepthCli, PlayShowsASyntheticSceneWithItsDepth) {
  TempDir dir;
  const CommandResult r =
      run_command("env -u DISPLAY LP_NUM_THREADS=2 " + std::string(NELF_BINARY) +
                  " play synthetic:scene=planes,duration=0.5,size=320x180 --output offscreen --no-audio --depth auto "
                  "--profile " +
                  q(write_small_profile(dir)));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("--depth"), std::string::npos) << r.err;
  unsigned shown = 0, repeated = 0, dropped = 0;
  const auto line = r.err.rfind("nelf: ", r.err.find("frames shown"));
  ASSERT_NE(line, std::string::npos) << r.err;
  ASSERT_EQ(
      std::sscanf(r.err.c_str() + line, "nelf: %u frames shown, %u repeated, %u dropped", &shown, &repeated, &dropped),
      3)
      << r.err;
  EXPECT_EQ(shown + dropped, 12u) << r.err;  // 0.5 s at 24 fps
}

}  // namespace
}  // namespace nelf::test
