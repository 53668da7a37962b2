// Live games from the command line (private Xvfb, the test game): `nelf convert x11:window=…`
// records what the HMD would show until --duration or Ctrl-C, with a complete file either way;
// `nelf play x11:window=…` plays a window until it closes; `nelf run -- GAME` starts the game,
// plays its window and ends with it, with its status; what cannot start is one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "game/planes_scene.hpp"
#include "inputs/glx_stereo_protocol.hpp"
#include "inputs/glx_stereo_source.hpp"
#include "support/test_game.hpp"
#include "support/test_support.hpp"
#include "support/xvfb.hpp"

namespace nelf {
namespace {

using namespace std::chrono_literals;
using test::run_command;
using test::run_nelf;
using test::q;
using test::shell_quote;

class LiveCliTest : public ::testing::Test {
 protected:
  test::XvfbServer xvfb_;
  test::ScopedDisplay display_env_{xvfb_.display_name()};
  test::TempDir dir_;
};

TEST_F(LiveCliTest, ConvertRecordsAGameWindowForTheHmd) {
  test::TestGame game({"--mode", "sbs", "--size", "320x180", "--fps", "30", "--title", "record me"});
  const auto out = dir_.path() / "game.mkv";
  const auto r = run_nelf("convert " + shell_quote("x11:wait=10,window=record me") + " " + q(out) + " --duration 2");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("window 0x"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("layout sbs (aspect)"), std::string::npos) << r.err;
  const std::string stream = run_command(
                                 "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
                                 "stream=width,height,nb_read_frames -of csv=p=0 " +
                                 q(out))
                                 .out;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(stream, m, std::regex("1280,1470,(\\d+)"))) << stream;  // hmz-t1: frame packing
  EXPECT_GE(std::stoi(m[1]), 20) << "2 s of a 30 fps game";
}

TEST_F(LiveCliTest, CtrlCEndsARecordingWithACompleteFile) {
  // --duration: were Ctrl-C missed, the test fails rather than waits for ever.
  test::TestGame game({"--mode", "tab", "--size", "320x180", "--fps", "30", "--title", "stop me", "--duration", "60"});
  const auto out = dir_.path() / "stopped.mkv";
  const auto r = run_command("( " + std::string(NELF_BINARY) + " convert " + shell_quote("x11:wait=10,window=stop me") +
                             " " + q(out) + " & pid=$!; sleep 3; kill -INT $pid; wait $pid; echo status=$? )");
  EXPECT_NE(r.out.find("status=0"), std::string::npos) << r.out << r.err;
  EXPECT_NE(r.err.find("layout tab (aspect)"), std::string::npos) << r.err;
  ASSERT_TRUE(std::filesystem::exists(out)) << r.err;
  const auto decoded = run_command("ffmpeg -v error -i " + q(out) + " -f null -");
  EXPECT_EQ(decoded.status, 0);
  EXPECT_EQ(decoded.err, "") << "every frame decodes";
  const auto frames = run_command(
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
      "stream=nb_read_frames -of csv=p=0 " +
      q(out));
  EXPECT_GE(std::stoi(frames.out), 10) << frames.out;
}

TEST_F(LiveCliTest, PlayShowsAWindowUntilItCloses) {
  test::TestGame game({"--mode", "sbs", "--size", "320x180", "--fps", "30", "--duration", "6", "--title", "watch me"});
  const auto log = dir_.path() / "frames.csv";
  const auto r =
      run_nelf("play " + shell_quote("x11:wait=10,window=watch me") + " --output offscreen --log-frames " + q(log));
  ASSERT_EQ(r.status, 0) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex("(\\d+) frames shown"))) << r.err;
  EXPECT_GE(std::stoi(m[1]), 5) << r.err;  // the player starts in ~1 s on two loaded software cores
  EXPECT_TRUE(game.wait_exit(5s));
}

TEST_F(LiveCliTest, RunStartsTheGamePlaysItsWindowAndEndsWithIt) {
  const auto log = dir_.path() / "frames.csv";
  const auto r = run_nelf("run --output offscreen --log-frames " + q(log) + " -- " + shell_quote(NELF_TEST_GAME) +
                          " --mode sbs --size 320x180 --fps 30 --duration 6");
  ASSERT_EQ(r.status, 0) << r.err;
  // Its picture, read by nelf's interposer at each swap (not through the X server).
  EXPECT_NE(r.err.find("the window of an OpenGL game (process "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("640x180 read at each swap, two 320x180 views, layout sbs (aspect)"), std::string::npos)
      << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex("(\\d+) frames shown"))) << r.err;
  EXPECT_GE(std::stoi(m[1]), 5) << r.err;  // the player starts in ~1 s on two loaded software cores
  // --log-frames names the game frame each refresh showed, read from the stamp in the views.
  EXPECT_TRUE(std::regex_search(test::read_file(log), std::regex(",\\d+,\\d+,\\d+,\\d+\n")));
  // --window: that window, captured through the X server, whatever draws it.
  const auto named =
      run_nelf("run --output offscreen --window " + shell_quote("named game") + " -- " + shell_quote(NELF_TEST_GAME) +
               " --mode sbs --size 320x180 --fps 30 --duration 4 --title " + shell_quote("named game"));
  ASSERT_EQ(named.status, 0) << named.err;
  EXPECT_NE(named.err.find("\"named game\""), std::string::npos) << named.err;
  EXPECT_NE(named.err.find("layout sbs (aspect)"), std::string::npos) << named.err;
  // The game's own options after --, the layout nelf's (a 640x180 window read as half SBS).
  const auto half = run_nelf("run --output offscreen --layout sbs-half -- " + shell_quote(NELF_TEST_GAME) +
                             " --mode sbs-half --size 320x180 --fps 30 --duration 1");
  ASSERT_EQ(half.status, 0) << half.err;
  EXPECT_NE(half.err.find("two 160x180 views, layout sbs-half (flag)"), std::string::npos) << half.err;
}

TEST_F(LiveCliTest, RunGivesAQuadBufferGameBothEyes) {
  // The test game asks for quad-buffer stereo, which Mesa does not have: under nelf run it opens its
  // window all the same and both its eyes are played, through GLFW and through SDL2.
  for (const char* toolkit : {"glfw", "sdl2"}) {
    SCOPED_TRACE(toolkit);
    const auto log = dir_.path() / (std::string(toolkit) + ".csv");
    const auto r = run_nelf("run --output offscreen --log-frames " + q(log) + " -- " + shell_quote(NELF_TEST_GAME) +
                            " --toolkit " + toolkit + " --mode quad-buffer --size 320x180 --fps 30 --duration 5");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("a quad-buffer OpenGL game, two 320x180 eyes, live"), std::string::npos) << r.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.err, m, std::regex("(\\d+) frames shown"))) << r.err;
    EXPECT_GE(std::stoi(m[1]), 5) << r.err;
    // --log-frames names the game frame each refresh showed, read from the stamp in the view.
    const std::string frames = test::read_file(log);
    EXPECT_TRUE(std::regex_search(frames, std::regex(",\\d+,\\d+,\\d+,\\d+\n"))) << frames.substr(0, 400);
  }
  // A game drawing both eyes into one window: its picture, split by its layout.
  const auto window = run_nelf("run --output offscreen -- " + shell_quote(NELF_TEST_GAME) +
                               " --mode sbs --size 320x180 --fps 30 --duration 3");
  ASSERT_EQ(window.status, 0) << window.err;
  EXPECT_NE(window.err.find("layout sbs (aspect)"), std::string::npos) << window.err;
}

TEST_F(LiveCliTest, RunGivesTheGamesDepthToTheCompositor) {
  // `--depth auto` under nelf run: the eyes' depth buffers come from the interposer and are related
  // to the views. The relation nelf finds is the one the test game's projection and cameras make:
  // glFrustum's depth value is a − b/z (a = f/(f−n), b = f·n/(f−n)) and the disparity F·e·(1/z − 1/c),
  // so disparity = F·e·(a/b − 1/c) − (F·e/b) · depth value (planes_scene.hpp).
  const auto r = run_nelf("run --depth auto --output offscreen -- " + shell_quote(NELF_TEST_GAME) +
                          " --mode quad-buffer --scene planes --size 320x180 --fps 30 --duration 4");
  ASSERT_EQ(r.status, 0) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      r.err, m,
      std::regex(
          "depth from the game's depth buffers \\(disparity (-?[0-9.]+) px \\+ (-?[0-9.]+) px x depth value\\)")))
      << r.err;
  using namespace test_game;
  const double a = kFarClip / (kFarClip - kNearClip), b = kFarClip * kNearClip / (kFarClip - kNearClip);
  const double fe = 0.5 * 320 / half_fov_tangent() * kEyeSeparation;
  const double offset = fe * (a / b - 1 / kConvergence), slope = -fe / b;
  EXPECT_NEAR(std::stod(m[1]), offset, 0.03 * std::abs(offset)) << r.err;
  EXPECT_NEAR(std::stod(m[2]), slope, 0.03 * std::abs(slope)) << r.err;
  // A game that draws without depth (the flat bars): said once, and its depth estimated instead.
  const auto flat = run_nelf("run --depth auto --output offscreen -- " + shell_quote(NELF_TEST_GAME) +
                             " --mode quad-buffer --size 320x180 --fps 30 --duration 2");
  ASSERT_EQ(flat.status, 0) << flat.err;
  const std::string said =
      "the game's depth buffers are empty (it draws without depth, or into framebuffers of its "
      "own); its depth is estimated from the views meanwhile";
  ASSERT_NE(flat.err.find(said), std::string::npos) << flat.err;
  EXPECT_EQ(flat.err.find(said, flat.err.find(said) + 1), std::string::npos) << flat.err;  // once
}

TEST_F(LiveCliTest, RunPacesAGameThatAsksForVsyncToTheDisplaysRefreshes) {
  // A quad-buffer game that asks for a swap interval of N has its swaps return in time for every
  // N-th of nelf's refreshes (the offscreen display's 60 Hz), as vsync does on a monitor; one that
  // asks for 0 paces itself (here at 250 fps, not flat out: the other tests share the cores). So
  // does a game that draws both eyes into one picture. The game's own log says when it presented
  // each frame.
  const auto median_interval_ms = [&](int interval, const std::string& mode = "quad-buffer") {
    const auto log = dir_.path() / ("game" + std::to_string(interval) + mode + ".csv");
    const auto r = run_nelf("run --output offscreen --no-audio -- " + shell_quote(NELF_TEST_GAME) + " --mode " + mode +
                            " --size 320x180 --fps 250 --duration 3 --swap-interval " + std::to_string(interval) +
                            " --log " + q(log));
    EXPECT_EQ(r.status, 0) << r.err;
    std::ifstream in(log);
    std::string line;
    std::getline(in, line);  // frame,present_ns
    std::vector<std::int64_t> presents;
    while (std::getline(in, line)) presents.push_back(std::stoll(line.substr(line.find(',') + 1)));
    std::vector<double> intervals;
    for (std::size_t i = 1; i < presents.size(); ++i)
      if (presents[i] - presents.front() > 1'000'000'000)  // nelf playing by then
        intervals.push_back((presents[i] - presents[i - 1]) / 1e6);
    if (intervals.empty()) return 0.0;
    std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
    return intervals[intervals.size() / 2];
  };
  const double free = median_interval_ms(0), every = median_interval_ms(1), every_other = median_interval_ms(2);
  const double picture = median_interval_ms(1, "sbs");
  std::printf("the game's median frame interval: swap interval 0 %.2f ms, 1 %.2f ms, 2 %.2f ms; sbs, 1 %.2f ms\n", free,
              every, every_other, picture);
  EXPECT_GT(free, 0.0);
  EXPECT_LT(free, 8.0);  // 4 ms asked
  EXPECT_NEAR(every, 1000.0 / 60, 3.0);
  EXPECT_NEAR(every_other, 2000.0 / 60, 4.0);
  EXPECT_NEAR(picture, 1000.0 / 60, 3.0);
}

TEST_F(LiveCliTest, SimulateShowsWhatTheEyeSeesOfAGamesFrameWithItsDepth) {
  // simulate takes a quad-buffer game's frame (the game started with the interposer by hand) and,
  // with --depth auto, composites it with the game's own depth, against the scene at that depth.
  const std::string socket = (dir_.path() / "game.sock").string();
  test::TestGame game(
      {"--mode", "quad-buffer", "--scene", "planes", "--size", "320x180", "--fps", "30"},
      {"LD_PRELOAD=" + glx_stereo_library_path(), std::string(glx_stereo::kSocketVariable) + "=" + socket});
  const auto json_of = [&](const std::string& depth) {
    const auto r = run_nelf("simulate " + shell_quote("glx-stereo:wait=20,socket=" + socket) + " --depth " + depth +
                            " --json -o " + q(dir_.path() / (depth + ".png")));
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(r.out);
  };
  const nlohmann::json with_depth = json_of("auto");
  EXPECT_EQ(with_depth["depth_used"], "game") << with_depth.dump();
  const nlohmann::json flat = json_of("off");
  EXPECT_EQ(flat["depth_used"], "none") << flat.dump();
  // Both against the same real scene (the game's depth, asked for whatever --depth says), and the
  // composite follows that depth only with auto: the retinas differ.
  EXPECT_EQ(with_depth["reference"], "scene") << with_depth.dump();
  EXPECT_EQ(flat["reference"], "scene") << flat.dump();
  EXPECT_GT(std::abs(with_depth["psnr_db"].get<double>() - flat["psnr_db"].get<double>()), 0.05)
      << with_depth.dump() << "\n"
      << flat.dump();
}

TEST_F(LiveCliTest, FfmpegCaptureDevicesAreInputsToo) {
  // lavfi: a filter graph read as a device; x11grab: FFmpeg's own screen grabber on this Xvfb.
  const auto graph = dir_.path() / "graph.mkv";
  const auto r = run_nelf("convert " + shell_quote("device:lavfi:testsrc2=size=640x180:rate=30") + " " + q(graph) +
                          " --duration 1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("layout sbs (aspect)"), std::string::npos) << r.err;
  const auto frames = [](const std::filesystem::path& file) {
    return run_command(
               "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
               "stream=width,height,nb_read_frames -of csv=p=0 " +
               q(file))
        .out;
  };
  EXPECT_EQ(frames(graph), "1280,1470,30\n");
  const auto screen = dir_.path() / "screen.mkv";
  const auto grabbed = run_nelf("convert " + shell_quote("device:x11grab:" + xvfb_.display_name()) + " " + q(screen) +
                                " --layout mono --frames 5");
  ASSERT_EQ(grabbed.status, 0) << grabbed.err;
  EXPECT_EQ(frames(screen), "1280,1470,5\n");
  // The device's own options, as ffmpeg takes -video_size before -i: x11grab grabs 320x240 of the screen.
  const auto corner = run_nelf(
      "convert " + shell_quote("device:x11grab:" + xvfb_.display_name()) + " " + q(dir_.path() / "corner.mkv") +
      " --layout mono --frames 2 --device-option video_size=320x240 --device-option framerate=10");
  ASSERT_EQ(corner.status, 0) << corner.err;
  EXPECT_NE(corner.err.find(": 320x240 rawvideo, layout mono"), std::string::npos) << corner.err;
}

TEST_F(LiveCliTest, DeviceOptionsAreTheDevicesOwnOrOneLine) {
  const std::string device = shell_quote("device:lavfi:testsrc2=size=640x180:rate=30");
  test::expect_clean_failure(dir_, "convert " + device + " out.mkv --duration 1 --device-option nosuch=1", 1,
                             "the lavfi device has no option nosuch (--device-option; ffmpeg -h demuxer=lavfi");
  test::expect_clean_failure(dir_, "convert " + device + " out.mkv --duration 1 --device-option video_size", 2,
                             "--device-option video_size: KEY=VALUE");
  test::expect_clean_failure(dir_, "convert synthetic: out.mkv --frames 1 --device-option video_size=1x1", 2,
                             "--device-option is for capture devices");
  test::expect_clean_failure(dir_, "play synthetic: --output offscreen --device-option video_size=1x1", 2,
                             "--device-option is for capture devices");
}

TEST_F(LiveCliTest, ProbeSaysItDescribesFiles) {
  test::expect_clean_failure(dir_, "probe x11:window=anything", 2,
                             "probe describes media files; a live input is described by play and convert");
  test::expect_clean_failure(dir_, "probe device:lavfi:testsrc2", 2, "probe describes media files");
}

TEST_F(LiveCliTest, RunFollowsTheGameToItsNextWindow) {
  // A splash window first, then the game's: both are played, and the game's status is nelf's.
  const auto r = run_nelf("run --output offscreen -- " + shell_quote(NELF_TEST_GAME) +
                          " --mode sbs --size 320x180 --fps 30 --reopen-after 60 --frames 150 --exit-status 7");
  EXPECT_EQ(r.status, 7) << r.err;
  EXPECT_NE(r.err.find("the game's window closed; waiting for its next one"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("exited with status 7"), std::string::npos) << r.err;
  std::smatch m;
  std::string rest = r.err;
  int plays = 0;
  while (std::regex_search(rest, m, std::regex("(\\d+) frames shown"))) {
    ++plays;
    // Each window is a new start of the player (shaders, tables): on two software cores that
    // takes most of a second, so only a part of the window's 2 or 3 s is shown.
    EXPECT_GE(std::stoi(m[1]), 2) << r.err;
    rest = m.suffix();
  }
  EXPECT_EQ(plays, 2) << r.err;
}

TEST_F(LiveCliTest, RunEndsWithTheGamesStatus) {
  const auto r = run_nelf("run --output offscreen -- sh -c 'exit 3'");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("ended without opening a window (the game exited with status 3)"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  const auto missing = run_nelf("run --output offscreen -- /no/such/game");
  EXPECT_EQ(missing.status, 127);
  EXPECT_NE(missing.err.find("/no/such/game: cannot start it"), std::string::npos) << missing.err;
  const auto none = run_nelf("run --output offscreen");
  EXPECT_EQ(none.status, 2);
  EXPECT_NE(none.err.find("nelf run [options] -- GAME [ARGS...]"), std::string::npos) << none.err;
}

// The game keeps its freed memory for reuse (glibc's tunables), and what the user set still wins.
TEST_F(LiveCliTest, RunHasTheGameKeepFreedMemoryForReuse) {
  const auto seen = dir_.path() / "tunables.txt";
  const std::string ours = "glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=268435456";
  const std::string game = " run --output offscreen -- sh -c " +
                           shell_quote("printf %s \"$GLIBC_TUNABLES\" > " + shell_quote(seen.string()) + "; exit 3");
  auto r = run_command("env -u GLIBC_TUNABLES " + std::string(NELF_BINARY) + game);
  ASSERT_EQ(r.status, 3) << r.err;
  EXPECT_EQ(test::read_file(seen), ours);
  r = run_command("env GLIBC_TUNABLES=glibc.malloc.trim_threshold=0 " + std::string(NELF_BINARY) + game);
  ASSERT_EQ(r.status, 3) << r.err;
  EXPECT_EQ(test::read_file(seen), ours + ":glibc.malloc.trim_threshold=0");
}

TEST_F(LiveCliTest, InterruptingRunEndsTheGameToo) {
  const auto r =
      run_command("( " + std::string(NELF_BINARY) + " run --output offscreen -- " + shell_quote(NELF_TEST_GAME) +
                  " --mode sbs --size 320x180 --fps 30 --duration 60 & pid=$!; sleep 3; kill -INT $pid; wait $pid; "
                  "echo status=$? )");
  EXPECT_NE(r.out.find("status=130"), std::string::npos) << r.out << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex("an OpenGL game \\(process (\\d+)\\)"))) << r.err;
  EXPECT_FALSE(std::filesystem::exists("/proc/" + m[1].str())) << "the game was left running";
  // Before the game has a window: nelf stops waiting for it and ends it.
  const auto start = std::chrono::steady_clock::now();
  const auto waiting = run_command("( " + std::string(NELF_BINARY) +
                                   " run --output offscreen -- sleep 37.5 & pid=$!; sleep 1; kill -INT $pid; "
                                   "wait $pid; echo status=$?; pgrep -f '^sleep 37.5$' || echo gone )");
  EXPECT_NE(waiting.out.find("status=130"), std::string::npos) << waiting.out << waiting.err;
  EXPECT_NE(waiting.out.find("gone"), std::string::npos) << waiting.out;
  // (A game first gets 5 s to swap an OpenGL frame, quad-buffer games give both eyes that way.)
  EXPECT_NE(waiting.err.find("interrupted while waiting for the game's first frame"), std::string::npos) << waiting.err;
  EXPECT_LT(std::chrono::steady_clock::now() - start, 10s);
}

}  // namespace
}  // namespace nelf
