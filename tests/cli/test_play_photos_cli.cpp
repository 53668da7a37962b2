// `nelf play` with photos, playlists and memory, off screen, driven by keys scripted on stdin (one
// per refresh): a photo stays until a key or --image-duration, several inputs, a folder or an .m3u
// play in turn and the keys step through them, --start and resuming start in the movie's time, and
// bad entries and damaged records cost one line, not the run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/frame_log.hpp"
#include "support/image_files.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf::test {
namespace {

namespace fs = std::filesystem;

double first_shown_pts(const fs::path& log) {
  for (const LogRow& row : read_log(log))
    if (row.event == "shown") return row.pts;
  return -1;
}

class PlayPhotos : public ::testing::Test {
 protected:
  TempDir dir_;
  fs::path profile_ = write_small_profile(dir_);
  fs::path state_ = dir_ / "state";

  // `nelf play ARGS` off screen, without sound, with `keys` typed on stdin and its own state folder.
  CommandResult play(const std::string& args, const std::string& keys = "") {
    const fs::path keys_file = dir_ / "keys";
    write_file(keys_file, keys);
    return run_command("timeout 120 env -u DISPLAY LP_NUM_THREADS=2 XDG_STATE_HOME=" + q(state_) + " " + NELF_BINARY +
                       " play " + args + " --profile " + q(profile_) + " --output offscreen --no-audio < " +
                       q(keys_file));
  }
  fs::path photo(const std::string& name, const std::string& colour = "red") {
    return write_lavfi_still(dir_, name, "color=c=" + colour + ":s=64x18");
  }
  fs::path clip(const std::string& name, double seconds) {
    return make_media(dir_ / name, "-f lavfi -i testsrc=s=128x36:r=24:d=" + std::to_string(seconds) + h264);
  }
  std::vector<fs::path> records() const {
    std::vector<fs::path> files;
    if (fs::exists(state_ / "nelf" / "watch_later"))
      for (const auto& e : fs::directory_iterator(state_ / "nelf" / "watch_later")) files.push_back(e.path());
    return files;
  }
};

// Positions of `needles` in `text`, in order; npos for one missing or out of order.
bool in_order(const std::string& text, const std::vector<std::string>& needles) {
  std::size_t at = 0;
  for (const std::string& n : needles) {
    at = text.find(n, at);
    if (at == std::string::npos) return false;
    at += n.size();
  }
  return true;
}

TEST_F(PlayPhotos, APhotoStaysOnScreenUntilAKey) {
  const fs::path p = photo("photo.jpg");
  const fs::path log = dir_ / "frames.csv";
  // Thirty eye swaps, one a refresh (500 ms at 60 Hz, far past the 40 ms a still used to last), then
  // q. Thirty, not eight: after a first frame slow to composite (a loaded machine) the offscreen
  // output catches up on its 60 Hz schedule without waiting, and eight refreshes once fit in 41 ms.
  const auto r = play(q(p) + " --layout sbs --log-frames " + q(log), std::string(30, 's') + "q");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = read_log(log);
  ASSERT_FALSE(rows.empty());
  // (The first may come with the first frame.)
  EXPECT_GE(std::count_if(rows.begin(), rows.end(), [](const LogRow& row) { return row.event == "redrawn"; }), 7)
      << r.err;
  EXPECT_GT(rows.back().clock, 0.06);  // past the 40 ms a still used to last
  EXPECT_NE(r.err.find("nelf: 1 frames shown, 0 repeated, 0 dropped"), std::string::npos) << r.err;
}

TEST_F(PlayPhotos, ImageDurationMakesASlideshow) {
  const fs::path a = photo("a.jpg"), b = photo("b.jpg", "blue");
  const fs::path log = dir_ / "frames.csv";
  const auto r = play(q(a) + " " + q(b) + " --layout sbs --image-duration 0.3 --log-frames " + q(log));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(
      in_order(r.err, {"nelf: 1/2: " + a.string(), "1 frames shown", "nelf: 2/2: " + b.string(), "1 frames shown"}))
      << r.err;
  const auto rows = read_log(log);  // the last file's
  ASSERT_FALSE(rows.empty());
  EXPECT_EQ(rows.front().event, "shown");
}

TEST_F(PlayPhotos, AFolderPlaysInNaturalOrderAndTheKeysStepThroughIt) {
  fs::create_directories(dir_ / "album");
  for (const char* name : {"album/p10.jpg", "album/p2.jpg", "album/p1.jpg"}) photo(name);
  write_file(dir_ / "album" / "notes.txt", "not a photo");
  // → → < q: p1, p2, p10, back to p2, quit.
  const auto r = play(q(dir_ / "album") + " --layout sbs", "\x1b[C\x1b[C<q");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string album = (dir_ / "album").string();
  EXPECT_TRUE(in_order(r.err, {"1/3: " + album + "/p1.jpg", "2/3: " + album + "/p2.jpg", "3/3: " + album + "/p10.jpg",
                               "2/3: " + album + "/p2.jpg"}))
      << r.err;
  EXPECT_EQ(r.err.find("notes.txt"), std::string::npos) << r.err;
  // Enter and > go on as → does; past the last file there is nothing to go to.
  const auto r2 = play(q(dir_ / "album") + " --layout sbs", "\r>>q");
  ASSERT_EQ(r2.status, 0) << r2.err;
  EXPECT_TRUE(in_order(r2.err, {"1/3:", "2/3:", "3/3:"})) << r2.err;
  EXPECT_EQ(r2.err.find("4/3"), std::string::npos) << r2.err;
}

TEST_F(PlayPhotos, APlaylistSkipsMissingAndBrokenEntriesWithOneLineEach) {
  photo("one.jpg");
  write_file(dir_ / "broken.jpg", "not a jpeg at all");
  clip("short.mkv", 0.5);
  write_file(dir_ / "list.m3u",
             "#EXTM3U\n# holiday\none.jpg\ngone.jpg\n\nbroken.jpg\n" + (dir_ / "short.mkv").string() + "\n");
  const auto r = play(q(dir_ / "list.m3u") + " --image-duration 0.1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: warning: " + (dir_ / "list.m3u").string() + " line 4: " + (dir_ / "gone.jpg").string() +
                       ": no such file, skipped\n"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("nelf: skipped: " + (dir_ / "broken.jpg").string()), std::string::npos) << r.err;
  EXPECT_TRUE(
      in_order(r.err, {"1/3: ", "one.jpg", "2/3: ", "broken.jpg", "skipped: ", "3/3: ", "short.mkv", "frames shown"}))
      << r.err;
}

TEST_F(PlayPhotos, EmptyFoldersAndPlaylistsAreOneLineErrors) {
  TempDir empty;
  fs::create_directories(empty / "nothing");
  write_file(empty / "none.m3u", "#EXTM3U\n# only comments\n");
  write_file(empty / "gone.m3u", "missing.mkv\n");
  expect_clean_failure(empty, "play " + q(empty / "nothing") + " --output offscreen", 2,
                       "the folder holds no image or video nelf plays");
  expect_clean_failure(empty, "play " + q(empty / "none.m3u") + " --output offscreen", 2,
                       "none.m3u: the playlist has no entry to play");
  const auto r = run_nelf("play " + q(empty / "gone.m3u") + " --output offscreen");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("gone.m3u line 1: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("gone.m3u: the playlist has no entry to play"), std::string::npos) << r.err;
  const auto bad = run_nelf("play " + q(empty / "x.jpg") + " --output offscreen --image-duration 0");
  EXPECT_EQ(bad.status, 2) << bad.err;
  EXPECT_NE(bad.err.find("--image-duration must be more than 0 seconds"), std::string::npos) << bad.err;
}

TEST_F(PlayPhotos, StartIsInTheMoviesTimeAndPastTheEndIsRefused) {
  const fs::path c = clip("clip.mkv", 4);
  const fs::path log = dir_ / "frames.csv";
  const auto r = play(q(c) + " --start 2.5 --log-frames " + q(log), "hq");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NEAR(first_shown_pts(log), 2.5, 1.0 / 24 + 1e-3) << r.err;
  const auto past = play(q(c) + " --start 9");
  EXPECT_EQ(past.status, 1) << past.err;
  EXPECT_NE(past.err.find("--start 9 is past the end of the video"), std::string::npos) << past.err;
}

TEST_F(PlayPhotos, PlayResumesWhereItWasStoppedAndRemembersTheSetUp) {
  const fs::path c = clip("clip.mkv", 30);
  const fs::path other = clip("other.mkv", 1);
  const fs::path log = dir_ / "frames.csv";
  // The other file's record, which damage to this one must leave alone.
  ASSERT_EQ(play(q(other) + " --layout sbs", "q").status, 0);
  ASSERT_EQ(records().size(), 1u);
  const fs::path other_record = records().front();
  const std::string other_text = read_file(other_record);

  // → seeks to 0:10, s swaps the eyes, q stops there.
  auto r = play(q(c) + " --layout sbs", "\x1b[Csq");
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(records().size(), 2u);
  fs::path record;
  for (const fs::path& f : records())
    if (f != other_record) record = f;
  const std::string text = read_file(record);
  EXPECT_NE(text.find("layout = 'sbs'"), std::string::npos) << text;
  EXPECT_NE(text.find("swap_eyes = true"), std::string::npos) << text;
  EXPECT_NE(text.find("position = 10"), std::string::npos) << text;

  r = play(q(c) + " --log-frames " + q(log), "hq");  // h: the first frame is shown before q
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: resuming at 0:00:10"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nelf: layout sbs as last time"), std::string::npos) << r.err;
  EXPECT_NEAR(first_shown_pts(log), 10.0, 1.0 / 24 + 1e-3) << r.err;

  r = play(q(c) + " --no-resume --log-frames " + q(log), "hq");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("resuming"), std::string::npos) << r.err;
  EXPECT_NEAR(first_shown_pts(log), 0.0, 1e-3);

  // A damaged record: one line, play from the start, the other file's record untouched.
  write_file(record, "position = [[[ not toml");
  r = play(q(c) + " --log-frames " + q(log), "hq");  // h: the first frame is shown before q
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the saved state of " + fs::canonical(c).string() + " is damaged"), std::string::npos) << r.err;
  EXPECT_NEAR(first_shown_pts(log), 0.0, 1e-3);
  EXPECT_EQ(read_file(other_record), other_text);
}

// Ctrl+s writes the packed frame as the display shows it, into the current folder under the first
// free name: the picture convert writes of the same photo, the right way up.
TEST_F(PlayPhotos, CtrlSWritesThePackedFrameAsConvertDoes) {
  const fs::path chart = write_lavfi_still(dir_, "chart.png", "testsrc2=s=256x72");
  const fs::path shots = dir_ / "shots";
  fs::create_directories(shots);
  write_file(dir_ / "keys", "\x13\x13q");
  const auto r =
      run_command("cd " + q(shots) + " && timeout 120 env -u DISPLAY LP_NUM_THREADS=2 XDG_STATE_HOME=" + q(state_) +
                  " " + NELF_BINARY + " play " + q(chart) + " --layout sbs --profile " + q(profile_) +
                  " --output offscreen --no-audio < " + q(dir_ / "keys"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(in_order(r.err, {"nelf: screenshot nelf-shot0001.png", "nelf: screenshot nelf-shot0002.png"})) << r.err;
  const auto converted = run_nelf("convert " + q(chart) + " " + q(dir_ / "converted.png") + " --layout sbs --profile " +
                                  q(profile_) + " --quiet");
  ASSERT_EQ(converted.status, 0) << converted.err;
  const ReadBack shot = read_back(shots / "nelf-shot0001.png"), want = read_back(dir_ / "converted.png");
  ASSERT_EQ(shot.width, want.width);
  ASSERT_EQ(shot.height, want.height);
  double same = 0, flipped = 0;
  for (int y = 0; y < shot.height; ++y)
    for (int x = 0; x < shot.width; ++x)
      for (int c = 0; c < 3; ++c) {
        same += std::abs(shot.at(x, y, c) - want.at(x, y, c));
        flipped += std::abs(shot.at(x, y, c) - want.at(x, shot.height - 1 - y, c));
      }
  const double n = 3.0 * shot.width * shot.height;
  EXPECT_LT(same / n, 0.01);
  EXPECT_GT(flipped / n, 50 * same / n + 0.001);  // the panels are mostly black: small means
}

// Ctrl+v: the views of the frame on screen side by side at the source's height, each at its display
// aspect (a half side-by-side movie's squeezed views widened again), with the subtitles, the eyes
// as the s key left them; written by a worker, so play goes on meanwhile.
TEST_F(PlayPhotos, CtrlVWritesTheViewsSideBySideWithTheSubtitles) {
  // Half side by side: red left, blue right, each squeezed to 160x180 of a 320x180 frame.
  make_media(dir_ / "movie.mkv", two_colour_input(160, 180, false, 20, 10) + h264);
  write_file(dir_ / "movie.srt", "1\n00:00:00,000 --> 00:00:05,000\nHELLO WORLD\n\n");
  const fs::path shots = dir_ / "shots";
  fs::create_directories(shots);
  write_file(dir_ / "keys", "\x16s\x16q");
  const auto r =
      run_command("cd " + q(shots) + " && timeout 120 env -u DISPLAY LP_NUM_THREADS=2 XDG_STATE_HOME=" + q(state_) +
                  " " + NELF_BINARY + " play " + q(dir_ / "movie.mkv") + " --layout sbs-half --profile " + q(profile_) +
                  " --output offscreen --no-audio < " + q(dir_ / "keys"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(in_order(r.err, {"nelf: screenshot nelf-views0001.png", "nelf: screenshot nelf-views0002.png"})) << r.err;
  for (const auto& [name, left_red] : {std::pair{"nelf-views0001.png", true}, std::pair{"nelf-views0002.png", false}}) {
    SCOPED_TRACE(name);
    const ReadBack views = read_back(shots / name);
    ASSERT_EQ(views.width, 640);  // two 320x180 views: 180 rows at 16:9
    ASSERT_EQ(views.height, 180);
    for (int half = 0; half < 2; ++half) {
      double red = 0, blue = 0;
      int letters = 0;
      for (int y = 0; y < 180; ++y)
        for (int x = half * 320; x < half * 320 + 320; ++x) {
          red += views.at(x, y, 0), blue += views.at(x, y, 2);
          letters += views.at(x, y, 1) > 0.5f && y > 120;  // neither red nor blue has green
        }
      const bool red_here = (half == 0) == left_red;
      EXPECT_GT(red_here ? red : blue, 3 * (red_here ? blue : red)) << "half " << half;
      EXPECT_GT(letters, 20) << "no subtitle in half " << half;
    }
  }
}

// A folder nothing can be written in (even by root: /proc) costs the screenshots (Ctrl+s, Ctrl+v),
// each with a warning that says why, and play goes on to its end.
TEST_F(PlayPhotos, AScreenshotThatCannotBeWrittenIsAWarning) {
  const fs::path chart = write_lavfi_still(dir_, "chart.png", "testsrc2=s=256x72");
  write_file(dir_ / "keys", "\x13\x16q");
  const auto r = run_command("cd /proc && timeout 120 env -u DISPLAY LP_NUM_THREADS=2 XDG_STATE_HOME=" + q(state_) +
                             " " + NELF_BINARY + " play " + q(chart) + " --layout sbs --profile " + q(profile_) +
                             " --output offscreen --no-audio < " + q(dir_ / "keys"));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto warning = r.err.find("nelf: warning: no screenshot: ");
  ASSERT_NE(warning, std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nelf-shot0001.png", warning), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("nelf: screenshot "), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists("/proc/nelf-shot0001.png"));
  const auto views = r.err.find("nelf: warning: no screenshot of the views: ");
  ASSERT_NE(views, std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nelf-views0001.png", views), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists("/proc/nelf-views0001.png"));
}

// An MPO (two JPEGs) and a JPS (right view first) read alike in probe and play: probe used to see
// an MPO's first JPEG only, as 2D.
TEST_F(PlayPhotos, MpoAndJpsReadAlikeInProbeAndPlay) {
  write_stereo_photos(dir_);
  const auto mpo = run_nelf("probe " + q(dir_ / "camera.mpo"));
  ASSERT_EQ(mpo.status, 0) << mpo.err;
  EXPECT_NE(mpo.out.find("layout:    pair (rule: metadata)\n"), std::string::npos) << mpo.out;
  const auto jps = run_nelf("probe " + q(dir_ / "photo.jps"));
  ASSERT_EQ(jps.status, 0) << jps.err;
  EXPECT_NE(jps.out.find("layout:    sbs, eyes swapped (rule: filename)\n"), std::string::npos) << jps.out;
  const auto played = play(q(dir_ / "camera.mpo") + " " + q(dir_ / "photo.jps") + " --image-duration 0.1");
  ASSERT_EQ(played.status, 0) << played.err;
  EXPECT_TRUE(in_order(played.err, {"camera.mpo: still image, two 32x18 views, layout pair (metadata)",
                                    "photo.jps: still image, two 32x18 views, layout sbs swapped (filename)"}))
      << played.err;
}

}  // namespace
}  // namespace nelf::test
