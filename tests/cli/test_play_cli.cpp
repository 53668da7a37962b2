// `nelf play` run as a user would, in a private Xvfb: the end of the file ends it cleanly with the
// one summary line; with sound on SDL's dummy driver (which consumes samples in real time) the
// audio clock is master and every new frame reaches the screen within one frame period of its
// time (from --log-frames); without sound the system clock paces it; bad inputs and outputs end in
// one clear line and the same status convert gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/frame_log.hpp"
#include "support/image_files.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"
#include "support/xvfb.hpp"

namespace nelf::test {
namespace {

// Side by side at `fps` for `seconds`: left red-ish, right blue-ish, a moving white box, and a
// 440 Hz tone unless `audio` is false.
std::filesystem::path make_clip(const TempDir& dir, const std::string& name, int seconds, int fps, bool audio = true) {
  return make_moving_box_clip(dir / name, seconds, fps, audio);
}

class PlayCli : public ::testing::Test {
 protected:
  XvfbServer xvfb_;
  TempDir dir_;
  std::string env(const std::string& audio_driver = "dummy") const {
    return "DISPLAY=" + xvfb_.display_name() + " SDL_AUDIODRIVER=" + audio_driver + " LP_NUM_THREADS=2 ";
  }
};

TEST_F(PlayCli, PlaysToTheEndInSyncWithTheAudioClockAndExitsCleanly) {
  const auto clip = make_clip(dir_, "clip.mp4", 2, 30);
  const auto log = dir_ / "frames.csv";
  const auto r = run_command(env() + NELF_BINARY + " play " + q(clip) + " --profile " + q(write_small_profile(dir_)) +
                             " --log-frames " + q(log));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: sound: dummy, 48000 Hz"), std::string::npos) << r.err;
  // The one summary line, and it adds up: every frame was either shown or dropped.
  const auto summary = r.err.find("frames shown, ");
  ASSERT_NE(summary, std::string::npos) << r.err;
  long shown = 0, repeated = 0, dropped = 0;
  ASSERT_EQ(std::sscanf(r.err.c_str() + r.err.rfind("nelf: ", summary),
                        "nelf: %ld frames shown, %ld repeated, %ld dropped", &shown, &repeated, &dropped),
            3)
      << r.err;
  EXPECT_EQ(shown + dropped, 60) << r.err;

  const auto rows = read_log(log);
  std::vector<double> offsets;
  for (const auto& row : rows) {
    if (row.event != "shown") continue;
    ASSERT_FALSE(row.audio_clock.empty()) << "no audio clock with sound";
    // The audio clock is the master clock.
    EXPECT_NEAR(std::stod(row.audio_clock), row.clock, 0.002);
    offsets.push_back(row.clock - row.pts);
  }
  ASSERT_EQ(static_cast<long>(offsets.size()), shown);
  // Each new frame reaches the screen within one frame period of its time. On a busy 2-core machine
  // (llvmpipe and other builds at load 10) a render now and then takes several frame periods, so
  // the check allows one frame in five to be late (measured here: 86–98 % within at load 7–10);
  // the typical offset must be well inside.
  std::size_t within = 0;
  for (double d : offsets) within += std::abs(d) <= 1.0 / 30 ? 1 : 0;
  EXPECT_GE(within * 5, offsets.size() * 4) << within << " of " << offsets.size() << " within one frame";
  std::vector<double> sorted = offsets;
  for (double& d : sorted) d = std::abs(d);
  std::sort(sorted.begin(), sorted.end());
  EXPECT_LE(sorted[sorted.size() / 2], 0.5 / 30) << "median offset";
}

TEST_F(PlayCli, VideoStartingAfterItsSoundStillStarts) {
  // Real files often start their video a little after their sound (B-frame delay: 0.023 s in an
  // x264 .mkv). The clock waits, paused, for the first frame on screen, and the first frame must
  // not wait for the clock: this used to hang for ever with nothing on screen.
  const std::string d = "1";
  const auto clip =
      make_media(dir_ / "late-video.mkv", "-itsoffset 0.3 -f lavfi -i color=c=0xC03020:s=320x90:r=24:d=" + d +
                                              " -f lavfi -i sine=f=440:r=48000:d=" + d + h264 + " -c:a aac");
  const auto r = run_command("timeout 60 env " + env() + NELF_BINARY + " play " + q(clip) + " --layout sbs-half" +
                             " --profile " + q(write_small_profile(dir_)));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: sound: dummy"), std::string::npos) << r.err;
  long shown = 0, repeated = 0, dropped = 0;
  const auto summary = r.err.rfind("nelf: ");
  ASSERT_EQ(std::sscanf(r.err.c_str() + summary, "nelf: %ld frames shown, %ld repeated, %ld dropped", &shown, &repeated,
                        &dropped),
            3)
      << r.err;
  EXPECT_EQ(shown + dropped, 24) << r.err;
  EXPECT_GT(shown, 0) << r.err;
}

// A 10-bit HEVC movie is composited as an 8-bit one is, from 8-bit block means on the CPU tables,
// its frames composited ahead on the worker: on llvmpipe the GL path for 16-bit views took ~55 ms a
// 1080p frame and dropped a third of a 24 fps movie's frames (docs/PERFORMANCE.md).
TEST_F(PlayCli, TenBitVideoIsCompositedAheadAsEightBitIs) {
  const auto clip = make_clip(dir_, "clip.mp4", 1, 24);
  const auto ten = make_media(dir_ / "ten.mkv", "-i " + q(clip) +
                                                    " -c:v libx265 -preset ultrafast -pix_fmt yuv420p10le "
                                                    "-x265-params log-level=error -c:a copy");
  for (const auto& input : {clip, ten}) {
    SCOPED_TRACE(input.filename().string());
    const auto log = dir_ / "frames.csv";
    const auto r = run_command(env() + NELF_BINARY + " play " + q(input) + " --no-audio --profile " +
                               q(write_small_profile(dir_)) + " --log-frames " + q(log));
    ASSERT_EQ(r.status, 0) << r.err;
    int shown = 0, ahead = 0;
    for (const auto& row : read_log(log))
      if (row.event == "shown") ++shown, ahead += row.ahead ? 1 : 0;
    // Played (half the clip at least: how many of the 24 a starved machine shows is the pacing
    // benchmark's business; 17 were seen on loaded cores), and nearly all of them composited ahead.
    EXPECT_GE(shown, 12);
    EXPECT_GE(ahead, shown - 2);  // the first frames may come before the worker has them
  }
}

TEST_F(PlayCli, NoAudioFlagPlaysOnTheSystemClock) {
  const auto clip = make_clip(dir_, "clip.mp4", 1, 24);
  const auto log = dir_ / "frames.csv";
  const auto r = run_command(env() + NELF_BINARY + " play " + q(clip) + " --no-audio --profile " +
                             q(write_small_profile(dir_)) + " --log-frames " + q(log));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: --no-audio: playing without sound\n"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("frames shown"), std::string::npos) << r.err;
  const auto rows = read_log(log);
  ASSERT_FALSE(rows.empty());
  for (const auto& row : rows) EXPECT_TRUE(row.audio_clock.empty());
  EXPECT_GT(rows.back().clock, 0.9);  // it took the clip's time, not less
}

TEST_F(PlayCli, NoAudioDeviceSaysWhyAndPlaysWithoutSound) {
  const auto clip = make_clip(dir_, "clip.mp4", 1, 24);
  const auto r = run_command(env("no-such-driver") + NELF_BINARY + " play " + q(clip) + " --profile " +
                             q(write_small_profile(dir_)));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: no audio device ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("): playing without sound\n"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("frames shown"), std::string::npos) << r.err;
}

TEST_F(PlayCli, AFileWithoutSoundPlaysOnTheSystemClock) {
  const auto clip = make_clip(dir_, "clip.mp4", 1, 24, false);
  const auto r = run_command(env() + NELF_BINARY + " play " + q(clip) + " --profile " + q(write_small_profile(dir_)));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: no audio stream: playing without sound\n"), std::string::npos) << r.err;
}

// The synthetic clip's tone is its sound, played and pacing the video as a file's audio does.
TEST_F(PlayCli, TheSyntheticClipPlaysItsTone) {
  const auto log = dir_ / "frames.csv";
  const auto r = run_command(env() + NELF_BINARY + " play synthetic:duration=1,size=160x90 --profile " +
                             q(write_small_profile(dir_)) + " --log-frames " + q(log));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: sound: dummy, 48000 Hz"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("playing without sound"), std::string::npos) << r.err;
  const auto rows = read_log(log);
  ASSERT_FALSE(rows.empty());
  for (const auto& row : rows) {
    if (row.event != "shown") continue;
    EXPECT_FALSE(row.audio_clock.empty()) << "no audio clock with sound";
  }
}

TEST_F(PlayCli, InterruptExitsWith130AndTheSummary) {
  const auto clip = make_clip(dir_, "long.mp4", 20, 24, false);
  const auto r =
      run_command(env() + std::string(NELF_BINARY) + " play " + q(clip) + " --profile " + q(write_small_profile(dir_)) +
                  " & pid=$!; sleep 3; kill -INT $pid; (sleep 30; kill -KILL $pid) 2>/dev/null & guard=$!; "
                  "wait $pid; status=$?; kill $guard; echo status $status");
  EXPECT_NE(r.out.find("status 130\n"), std::string::npos) << r.out << r.err;
  EXPECT_NE(r.err.find("frames shown"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nelf: interrupted\n"), std::string::npos) << r.err;
}

// Keys reach the player: → seeks 10 s forward, q quits with status 0 and the summary.
TEST_F(PlayCli, ArrowKeySeeksForwardAndQQuits) {
  const auto clip = make_clip(dir_, "long.mp4", 30, 24, false);
  const auto log = dir_ / "frames.csv";
  const auto r = run_command(
      env() + std::string(NELF_BINARY) + " play " + q(clip) + " --profile " + q(write_small_profile(dir_)) +
      " --log-frames " + q(log) +
      " & pid=$!; (sleep 60; kill -KILL $pid) 2>/dev/null & guard=$!; export DISPLAY=" + xvfb_.display_name() +
      "; w=$(timeout 20 xdotool search --sync --name '^nelf: ' | head -1); sleep 1.5; xdotool key --window $w Right; "
      "sleep 1.5; xdotool key --window $w q; wait $pid; status=$?; kill $guard; echo status $status");
  EXPECT_NE(r.out.find("status 0\n"), std::string::npos) << r.out << r.err;
  EXPECT_NE(r.err.find("frames shown"), std::string::npos) << r.err;
  const auto rows = read_log(log);
  ASSERT_FALSE(rows.empty());
  double first_after_seek = -1, last = 0;
  for (const auto& row : rows) {
    if (row.event != "shown") continue;
    if (first_after_seek < 0 && row.pts >= 10) first_after_seek = row.pts;
    last = row.pts;
  }
  EXPECT_GE(first_after_seek, 10.0) << "no frame after the seek";
  EXPECT_LT(first_after_seek, 15.0);
  EXPECT_LT(last, 20.0) << "q did not stop it";
}

// h shows the key help: every line of the play rows of the key table in the terminal (first press).
TEST_F(PlayCli, HPrintsTheKeyHelpFromTheTable) {
  const auto clip = make_clip(dir_, "long.mp4", 30, 24, false);
  const auto r = run_command(
      env() + std::string(NELF_BINARY) + " play " + q(clip) + " --profile " + q(write_small_profile(dir_)) +
      " & pid=$!; (sleep 60; kill -KILL $pid) 2>/dev/null & guard=$!; export DISPLAY=" + xvfb_.display_name() +
      "; w=$(timeout 20 xdotool search --sync --name '^nelf: ' | head -1); sleep 1.5; xdotool key --window $w h; "
      "sleep 1; xdotool key --window $w q; wait $pid; status=$?; kill $guard; echo status $status");
  EXPECT_NE(r.out.find("status 0\n"), std::string::npos) << r.out << r.err;
  for (const std::string line :
       {"space: pause / play", "left right: seek 10 s back / forward", "h: this help", "q Esc: quit"})
    EXPECT_NE(r.err.find("nelf: key " + line + "\n"), std::string::npos) << line << "\n" << r.err;
}

// A file cut in the middle (the file ending early): what decodes plays, the loss is counted in the
// summary line, and the end is a clean exit.
TEST_F(PlayCli, ATruncatedFilePlaysWhatDecodesAndCountsTheLoss) {
  make_media(dir_ / "whole.mkv", two_colour_input(320, 180, false, 12, 10) + " -c:v libx264 -preset ultrafast -g 1");
  const std::string bytes = read_file(dir_ / "whole.mkv");
  write_file(dir_ / "cut.mkv", bytes.substr(0, bytes.size() / 2));
  const auto r =
      run_command(env() + NELF_BINARY + " play " + q(dir_ / "cut.mkv") + " --profile " + q(write_small_profile(dir_)));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("video frames lost to decode errors"), std::string::npos) << r.err;
}

TEST_F(PlayCli, QuadBufferOnMesaIsAClearError) {
  const auto clip = make_clip(dir_, "clip.mp4", 1, 24, false);
  const auto r = run_command(env() + NELF_BINARY + " play " + q(clip) + " --output quad-buffer");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("no stereo visuals"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;  // the input line and the error
}

TEST_F(PlayCli, FullscreenOnAMissingMonitorIsAClearError) {
  const auto clip = make_clip(dir_, "clip.mp4", 1, 24, false);
  const auto r = run_command(env() + NELF_BINARY + " play " + q(clip) + " --output fullscreen --monitor NO-SUCH");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("NO-SUCH"), std::string::npos) << r.err;
}

TEST(PlayCliErrors, NoDisplayIsAClearError) {
  TempDir dir;
  const auto clip = make_clip(dir, "clip.mp4", 1, 24, false);
  const auto r = run_command("env -u DISPLAY " + std::string(NELF_BINARY) + " play " + q(clip));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("DISPLAY is not set"), std::string::npos) << r.err;
}

// What convert refuses, play refuses with the same line and status.
TEST(PlayCliErrors, BadInputsAsConvertSaysThem) {
  TempDir dir;
  write_file(dir / "notes.txt", "not a video\n");
  const auto clip = make_clip(dir, "clip.mp4", 1, 24, false);
  const std::vector<std::string> cases = {
      q(dir / "notes.txt"),           q(dir / "missing.mp4"),
      q(clip) + " --layout diagonal", q(clip) + " --profile no-such-profile",
      q(clip) + " --fsaa 3",          q(clip) + " --signal no-such-signal",
      q(clip) + " --layout pair",
  };
  for (const auto& args : cases) {
    SCOPED_TRACE(args);
    const auto play = run_command("env -u DISPLAY " + std::string(NELF_BINARY) + " play " + args);
    const auto convert = run_nelf("convert " + args.substr(0, args.find(' ')) + " " + q(dir / "out.mp4") +
                                  (args.find(' ') == std::string::npos ? "" : args.substr(args.find(' '))));
    EXPECT_NE(play.status, 0);
    EXPECT_EQ(play.status, convert.status) << play.err << convert.err;
    EXPECT_EQ(play.err, convert.err);
  }
  const auto output = run_command("env -u DISPLAY " + std::string(NELF_BINARY) + " play " + q(clip) + " --output hdmi");
  EXPECT_EQ(output.status, 2);
  EXPECT_NE(output.err.find("unknown output 'hdmi' (expected window, fullscreen, kms, quad-buffer or offscreen)"),
            std::string::npos)
      << output.err;
}

// A still's problems, read by the still driver in play as in convert: the same one line and status.
TEST(PlayCliErrors, AStillsProblemsAsConvertSaysThem) {
  TempDir dir;
  write_stereo_photos(dir);
  write_file(dir / "one.mpo", read_file(dir / "l.jpg"));
  write_file(dir / "cut.jpg", read_file(dir / "l.jpg").substr(0, 40));
  const std::vector<std::string> cases = {
      q(dir / "missing.jps"),
      q(dir / "one.mpo"),
      q(dir / "cut.jpg"),
      q(dir / "photo.jps") + " --layout alt",
      q(dir / "camera.mpo") + " --layout sbs",
  };
  for (const auto& args : cases) {
    SCOPED_TRACE(args);
    const auto play = run_command("env -u DISPLAY " + std::string(NELF_BINARY) + " play " + args);
    const auto convert = run_nelf("convert " + args.substr(0, args.find(' ')) + " " + q(dir / "out.png") +
                                  (args.find(' ') == std::string::npos ? "" : args.substr(args.find(' '))));
    EXPECT_NE(play.status, 0);
    EXPECT_EQ(play.status, convert.status) << play.err << convert.err;
    EXPECT_EQ(play.err, convert.err);
    EXPECT_EQ(std::count(play.err.begin(), play.err.end(), '\n'), 1) << play.err;
    EXPECT_EQ(play.err.rfind("nelf: ", 0), 0u) << play.err;
  }
}

// --gpu picks the EGL device headless rendering uses; play renders on its display's own GPU, so the
// option would be ignored: it is refused instead, before anything opens.
TEST(PlayCliErrors, GpuIsRefusedAsItCannotApply) {
  TempDir dir;
  const auto clip = make_clip(dir, "clip.mp4", 1, 24, false);
  const auto r = run_command("env -u DISPLAY " + std::string(NELF_BINARY) + " play " + q(clip) + " --gpu 0");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err,
            "nelf: --gpu picks the GPU of headless rendering (convert, simulate, calibrate --output FILE); "
            "play renders on its display's GPU (--output kms: NELF_DRM_DEVICE picks the card)\n");
}

}  // namespace
}  // namespace nelf::test

namespace nelf::test {
namespace {

// The offscreen output runs the real player loop with no display server: the clip plays to its end
// in its own time on the clock, and the summary counts every frame.
TEST(PlayOffscreen, PlaysWithoutADisplayServerAndPrintsTheSummary) {
  TempDir dir;
  const auto log = dir / "frames.csv";
  const auto started = std::chrono::steady_clock::now();
  const auto r = run_command("env -u DISPLAY LP_NUM_THREADS=2 " + std::string(NELF_BINARY) +
                             " play synthetic:duration=2 --output offscreen --no-audio --log-frames " + q(log));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: playing on offscreen 1280x1470 ("), std::string::npos) << r.err;
  unsigned shown = 0, repeated = 0, dropped = 0;
  const auto summary = r.err.find("frames shown");
  ASSERT_NE(summary, std::string::npos) << r.err;
  const auto line = r.err.rfind("nelf: ", summary);
  ASSERT_EQ(
      std::sscanf(r.err.c_str() + line, "nelf: %u frames shown, %u repeated, %u dropped", &shown, &repeated, &dropped),
      3)
      << r.err;
  EXPECT_EQ(shown + dropped, 48u) << r.err;  // 2 s at 24 fps
  const auto rows = read_log(log);
  ASSERT_FALSE(rows.empty());
  EXPECT_GT(rows.back().clock, 1.9);  // paced by the clock: the clip's time, not as fast as it renders
  EXPECT_GT(std::chrono::steady_clock::now() - started, std::chrono::seconds(2));
}

// A stereo photo plays off screen as its one frame, read by the still driver (OpenImageIO), for
// --image-duration.
TEST(PlayOffscreen, PlaysAJpsAndAnMpoAsTheirOneFrame) {
  TempDir dir;
  write_stereo_photos(dir);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"photo.jps", "photo.jps: still image, two 32x18 views, layout sbs swapped (filename)\n"},
      {"camera.mpo", "camera.mpo: still image, two 32x18 views, layout pair (metadata)\n"},
  };
  for (const auto& [name, described] : cases) {
    SCOPED_TRACE(name);
    const auto r = run_command("env -u DISPLAY LP_NUM_THREADS=2 " + std::string(NELF_BINARY) + " play " +
                               q(dir / name) + " --output offscreen --no-audio --image-duration 0.1 < /dev/null");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find(described), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("nelf: 1 frames shown, 0 repeated, 0 dropped\n"), std::string::npos) << r.err;
  }
}

// --gpu applies off screen (headless rendering), and a device EGL does not list is refused.
TEST(PlayOffscreen, TakesGpuAndRefusesADeviceEglDoesNotList) {
  const auto r = run_command("env -u DISPLAY " + std::string(NELF_BINARY) +
                             " play synthetic:duration=1 --output offscreen --no-audio --gpu 99");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("GPU 99 requested but EGL lists"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

}  // namespace
}  // namespace nelf::test
