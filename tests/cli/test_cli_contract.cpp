// The command line's small promises, checked as a user meets them: numbers that are numbers, a
// wrong --gpu always named, the network rule named for a playlist, --quiet that keeps warnings,
// one frame of a video written as an image, and a mistyped command or option answered with the
// nearest one.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "support/image_files.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf::test {
namespace {

// A plain 2D 16:9 clip: red for 0.5 s, then blue for 0.5 s, at 10 fps.
std::filesystem::path red_then_blue(const TempDir& dir) {
  return make_media(dir / "plain.mkv",
                    "-f lavfi -i color=c=red:s=320x180:r=10:d=0.5 -f lavfi -i color=c=blue:s=320x180:r=10:d=0.5 "
                    "-filter_complex concat=n=2:v=1:a=0" +
                        h264);
}

// `nelf ARGS` fails with exactly `line` (one line) and status 2.
void expect_usage_error(const std::string& args, const std::string& line) {
  SCOPED_TRACE(args);
  const auto r = run_nelf(args);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, line + "\n");
}

TEST(CliContract, NonFiniteNumbersAreRefused) {
  TempDir dir;
  const auto clip = red_then_blue(dir);
  const auto profile = write_small_profile(dir);
  const std::string convert = "convert " + q(clip) + " " + q(dir / "out.mkv") + " --profile " + q(profile) + " ";
  for (const std::string value : {"nan", "NaN", "inf", "infinity"}) {
    expect_clean_failure(dir, convert + "--start " + value, 2, "--start: must be a finite number, got " + value);
    expect_clean_failure(dir, convert + "--duration " + value, 2, "--duration: must be a finite number");
  }
  expect_clean_failure(dir, convert + "--start=-inf", 2, "--start: must be a finite number, got -inf");
  expect_clean_failure(dir, "simulate " + q(clip) + " -o " + q(dir / "eye.png") + " --pupil-mm inf", 2,
                       "--pupil-mm: must be a finite number");
  // Finite numbers still pass.
  const auto r = run_nelf(convert + "--start 0.2 --duration 0.3 --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "out.mkv"));
}

// The CPU path takes composite tables from the cache without starting GL; an explicit device that
// EGL does not list is refused all the same, in the words GL uses.
TEST(CliContract, MissingGpuIsReportedWhetherOrNotTheTablesAreCached) {
  TempDir dir, cache;
  const auto clip = red_then_blue(dir);
  const std::string env = "NELF_CACHE_DIR=" + q(cache.path()) + " NELF_COMPOSITE=table ";
  const auto convert = [&](const std::string& extra) {
    return run_command(env + shell_quote(NELF_BINARY) + " convert " + q(clip) + " " + q(dir / "out.mkv") +
                       " --profile hmz-t1 --layout mono --codec utvideo --quiet" + extra);
  };
  const auto uncached = convert(" --gpu 99");
  EXPECT_EQ(uncached.status, 1);
  EXPECT_NE(uncached.err.find("GPU 99 requested but EGL lists"), std::string::npos) << uncached.err;
  EXPECT_EQ(std::count(uncached.err.begin(), uncached.err.end(), '\n'), 1) << uncached.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.mkv"));

  ASSERT_EQ(convert("").status, 0);  // records the tables
  ASSERT_FALSE(files_in(cache / "composite-tables").empty());
  std::filesystem::remove(dir / "out.mkv");

  const auto cached = convert(" --gpu 99");
  EXPECT_EQ(cached.status, uncached.status);
  EXPECT_EQ(cached.err, uncached.err);
  EXPECT_FALSE(std::filesystem::exists(dir / "out.mkv"));
  const auto from_environment =
      run_command("NELF_GPU=99 " + env + shell_quote(NELF_BINARY) + " convert " + q(clip) + " " + q(dir / "out.mkv") +
                  " --profile hmz-t1 --layout mono --codec utvideo --quiet");
  EXPECT_EQ(from_environment.status, uncached.status);
  EXPECT_EQ(from_environment.err, uncached.err);
  EXPECT_FALSE(std::filesystem::exists(dir / "out.mkv"));
}

// A local playlist whose segments are on a server: refused before any connection, naming the
// option that allows it (port 9 is "discard": nothing listens, a connection attempt would fail
// differently or hang).
TEST(CliContract, PlaylistWithNetworkSegmentsNamesAllowNetwork) {
  TempDir dir;
  write_file(dir / "list.m3u8",
             "#EXTM3U\n#EXT-X-VERSION:3\n#EXT-X-TARGETDURATION:2\n#EXT-X-MEDIA-SEQUENCE:0\n"
             "#EXTINF:2.0,\nhttp://127.0.0.1:9/seg0.ts\n#EXTINF:2.0,\nhttp://127.0.0.1:9/seg1.ts\n#EXT-X-ENDLIST\n");
  const std::string list = q(dir / "list.m3u8");
  const auto started = std::chrono::steady_clock::now();
  expect_clean_failure(dir, "probe " + list, 1,
                       "list.m3u8: opening it needs network access (http); pass --allow-network");
  expect_clean_failure(dir, "convert " + list + " " + q(dir / "out.mkv"), 1, "pass --allow-network");
  // A live playlist (no #EXT-X-ENDLIST) is reloaded every target duration while its segments fail:
  // the refusal must end the opening, not 1000 reloads.
  write_file(dir / "live.m3u8", "#EXTM3U\n#EXT-X-TARGETDURATION:1\n#EXTINF:1,\nhttp://127.0.0.1:9/a.ts\n");
  expect_clean_failure(dir, "probe " + q(dir / "live.m3u8"), 1,
                       "live.m3u8: opening it needs network access (http); pass --allow-network");
  // The same for a local live playlist whose segment does not open: two reloads, not 1000.
  write_file(dir / "local-live.m3u8", "#EXTM3U\n#EXT-X-TARGETDURATION:1\n#EXTINF:1,\nmissing.ts\n");
  expect_clean_failure(dir, "probe " + q(dir / "local-live.m3u8"), 1, "local-live.m3u8: not a media file");
  // Each reload of a live playlist waits its target duration: opening a local file is given up
  // after 15 s (it waited 2 x 100 s before).
  write_file(dir / "slow-live.m3u8", "#EXTM3U\n#EXT-X-TARGETDURATION:100\n#EXTINF:100,\nmissing.ts\n");
  expect_clean_failure(dir, "probe " + q(dir / "slow-live.m3u8"), 1,
                       "slow-live.m3u8: still not open after 15 s, given up");
  expect_clean_failure(dir, "probe http://127.0.0.1:9/film.mkv", 1,
                       "needs network access (http); pass --allow-network");
  EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(45));
}

// --quiet hides progress, not warnings: a 2D clip still says it is shown as 2D.
TEST(CliContract, QuietKeepsWarnings) {
  TempDir dir;
  const auto clip = red_then_blue(dir);
  const auto profile = write_small_profile(dir);
  const auto r = run_nelf("convert " + q(clip) + " " + q(dir / "out.mkv") + " --profile " + q(profile) + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("nelf: warning: no stereo layout detected for"), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;  // no progress, no summary
}

// Mean red and blue over the small profile's panel in the top eye of the 1280x1470 packed frame
// (the 160x90 panel sits centred in the 1280x720 eye area).
std::pair<double, double> panel_red_blue(const ReadBack& image) {
  double red = 0, blue = 0;
  int n = 0;
  for (int y = 315; y < 405; ++y)
    for (int x = 560; x < 720; ++x, ++n) red += image.at(x, y, 0), blue += image.at(x, y, 2);
  return {red / n, blue / n};
}

TEST(CliContract, OneFrameOfAVideoToAnImage) {
  TempDir dir;
  const auto clip = red_then_blue(dir);
  const auto profile = write_small_profile(dir);
  const std::string convert = "convert " + q(clip) + " --profile " + q(profile) + " ";

  auto r = run_nelf(convert + q(dir / "first.png"));
  ASSERT_EQ(r.status, 0) << r.err;
  const ReadBack first = read_back(dir / "first.png");
  EXPECT_EQ(first.width, 1280);
  EXPECT_EQ(first.height, 1470);
  const auto [first_red, first_blue] = panel_red_blue(first);
  EXPECT_GT(first_red, 3 * first_blue);

  r = run_nelf(convert + q(dir / "later.png") + " --start 0.7 --frames 1");
  ASSERT_EQ(r.status, 0) << r.err;
  const ReadBack later = read_back(dir / "later.png");
  EXPECT_EQ(later.width, 1280);
  EXPECT_EQ(later.height, 1470);
  const auto [later_red, later_blue] = panel_red_blue(later);
  EXPECT_GT(later_blue, 3 * later_red);

  // More than one frame needs a name for each; a failed conversion leaves no image.
  expect_clean_failure(dir, convert + q(dir / "x.png") + " --frames 5", 2,
                       "x.png holds one frame; for 5 frames name an image sequence such as");
  expect_clean_failure(dir, convert + q(dir / "x.png") + " --duration 0.5", 2, "x_%05d.png");
  expect_clean_failure(dir, convert + q(dir / "x.png") + " --start 5", 1, "is past the end of the video");
  expect_clean_failure(dir, convert + q(dir / "first.png"), 1, "pass -y to overwrite");
  EXPECT_EQ(files_in(dir.path()), (std::vector<std::string>{"first.png", "later.png", "plain.mkv", "small.toml"}));
}

TEST(CliContract, MistypedCommandsAndOptionsNameTheNearest) {
  TempDir dir;
  expect_usage_error("convrt in.mkv out.mkv", "nelf: unknown command 'convrt' (did you mean 'convert'?)");
  expect_usage_error("porbe in.mkv", "nelf: unknown command 'porbe' (did you mean 'probe'?)");
  expect_usage_error("frobnicate", "nelf: unknown command 'frobnicate' (see nelf --help)");
  expect_usage_error("--verison", "nelf: unknown option '--verison' (did you mean '--version'?)");
  expect_usage_error("convert --stat 5 in.mkv out.mkv",
                     "nelf: convert: unknown option '--stat' (did you mean '--start'?)");
  expect_usage_error("convert in.mkv out.mkv --stat=5",
                     "nelf: convert: unknown option '--stat' (did you mean '--start'?)");
  expect_usage_error("convert in.mkv out.mkv --overwrit",
                     "nelf: convert: unknown option '--overwrit' (did you mean '--overwrite'?)");
  expect_usage_error("play in.mkv --no-audoi", "nelf: play: unknown option '--no-audoi' (did you mean '--no-audio'?)");
  expect_usage_error("convert in.mkv out.mkv --zzzzzz",
                     "nelf: convert: unknown option '--zzzzzz' (see nelf convert --help)");
  // A negative number is a value, not an option.
  const auto r = run_nelf("simulate missing.png -o " + q(dir / "eye.png") + " --eye-offset-mm -1,0");
  EXPECT_EQ(r.err.find("unknown option"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace nelf::test
