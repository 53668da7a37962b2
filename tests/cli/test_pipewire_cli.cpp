// `pipewire:node=…` against a real PipeWire daemon and a real producer: each test starts its own
// daemon (`pipewire`, its socket in a private runtime directory that PIPEWIRE_RUNTIME_DIR names for
// every client) and GStreamer's videotestsrc into pipewiresink as the node, and stops them.
// GStreamer's pipewiresink (Debian 12) sends nothing more once its first reader has left, so each
// nelf run reads a node of its own.
//
// `pipewire:` alone goes through a desktop's stack, each test's own: a private session bus, the real
// xdg-desktop-portal front end it activates, WirePlumber linking the cast, and the desktop's half of
// the portal played by tests/desktop/screencast_portal_backend.cpp (answering for the user's dialog).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "support/image_files.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using namespace std::chrono_literals;

// Channels of two same-sized images that differ by more than 8-bit rounding (a live node's frame
// against nelf's output for the same picture as a file).
std::size_t differing_channels(const test::ReadBack& got, const test::ReadBack& expected) {
  std::size_t differing = 0;
  for (std::size_t i = 0; i < got.pixels.size(); ++i)
    if (std::abs(got.pixels[i] - expected.pixels[i]) > 2.5f / 255) ++differing;
  return differing;
}

// A program run in the background for a test, ended (SIGTERM, then SIGKILL) and reaped with it.
class Background {
 public:
  explicit Background(std::vector<std::string> args) {
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_ = fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      std::freopen("/dev/null", "w", stdout);
      std::freopen("/dev/null", "w", stderr);
      execvp(argv[0], argv.data());
      _exit(127);
    }
  }
  ~Background() { stop(); }
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;
  void stop() {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    for (int i = 0; i < 300; ++i) {
      if (waitpid(pid_, nullptr, WNOHANG) == pid_) {
        pid_ = -1;
        return;
      }
      std::this_thread::sleep_for(10ms);
    }
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
};

class PipeWireCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(chmod(runtime_.path().c_str(), 0700), 0);
    daemon_ = std::make_unique<Background>(std::vector<std::string>{"pipewire"});
    for (int i = 0; i < 500 && !std::filesystem::exists(runtime_ / "pipewire-0"); ++i)
      std::this_thread::sleep_for(10ms);
    ASSERT_TRUE(std::filesystem::exists(runtime_ / "pipewire-0")) << "the pipewire daemon did not start";
  }

  // GStreamer's SMPTE bars, WIDTHxHEIGHT in `format` at 30 fps, as the video node `name`.
  void start_node(const std::string& name, const std::string& format, int width = 640, int height = 180) {
    nodes_.push_back(std::make_unique<Background>(std::vector<std::string>{
        "gst-launch-1.0", "videotestsrc", "is-live=true", "pattern=smpte", "!",
        fmt::format("video/x-raw,format={},width={},height={},framerate=30/1", format, width, height), "!",
        "pipewiresink", "mode=provide", "stream-properties=props,media.class=Video/Source", "client-name=" + name}));
    for (int i = 0; i < 100; ++i) {
      if (test::run_command("pw-cli ls Node").out.find("node.name = \"" + name + "\"") != std::string::npos) return;
      std::this_thread::sleep_for(50ms);
    }
    FAIL() << "GStreamer's node " << name << " did not appear";
  }

  // The same bars as a still, through GStreamer's own conversion to RGB.
  std::filesystem::path bars_still(int width = 640, int height = 180) {
    const auto raw = dir_ / "bars.rgb", png = dir_ / "bars.png";
    const auto made = test::run_command(fmt::format(
        "gst-launch-1.0 -q videotestsrc num-buffers=1 pattern=smpte ! video/x-raw,format=BGRx,width={},height={} ! "
        "videoconvert ! video/x-raw,format=RGB ! filesink location={} && ffmpeg -v error -f rawvideo -pix_fmt rgb24 "
        "-s {}x{} -i {} -y {}",
        width, height, test::q(raw), width, height, test::q(raw), test::q(png)));
    EXPECT_EQ(made.status, 0) << made.err;
    std::filesystem::remove(raw);
    return png;
  }

  // What nelf makes of the bars as a file: the frame a node of the same bars must record as.
  void convert_bars_still(test::ReadBack& expected) {
    const auto still = bars_still();
    const auto reference = dir_ / "reference.png";
    ASSERT_EQ(test::run_nelf("convert " + test::q(still) + " " + test::q(reference)).status, 0);
    expected = test::read_back(reference);
  }

  test::TempDir dir_, runtime_;
  test::ScopedEnv remote_{"PIPEWIRE_RUNTIME_DIR", runtime_.path().string()};
  std::unique_ptr<Background> daemon_;
  std::vector<std::unique_ptr<Background>> nodes_;
};

TEST_F(PipeWireCliTest, ANodesFramesAreWhatTheSameStillWouldShow) {
  // Two pixel orders a producer may send (BGRx as Wayland compositors do, RGBx): the frame nelf
  // records from the node is the frame it makes of the same picture as a file.
  test::ReadBack expected;
  ASSERT_NO_FATAL_FAILURE(convert_bars_still(expected));
  for (const std::string format : {"BGRx", "RGBx"}) {
    SCOPED_TRACE(format);
    const std::string name = "bars-" + format;
    start_node(name, format);
    const auto out = dir_ / (name + ".png");
    const auto r = test::run_nelf("convert pipewire:node=" + name + " " + test::q(out) + " --frames 1");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("\"" + name + "\" (Video/Source), 640x180, live, two 320x180 views, layout sbs (aspect)"),
              std::string::npos)
        << r.err;
    const auto got = test::read_back(out);
    ASSERT_EQ(got.width, expected.width);
    ASSERT_EQ(got.height, expected.height);
    EXPECT_EQ(differing_channels(got, expected), 0u);
  }
}

TEST_F(PipeWireCliTest, YuvNodesAreWhatFfmpegMakesOfTheSameFrame) {
  // Cameras, capture cards and encoders' casts send YUV: nelf converts it (swscale) as ffmpeg
  // converts the same raw frame, so the recording is nelf's conversion of ffmpeg's picture of it.
  // I420 (one plane a spa_data, as GStreamer sends it) and YUY2 (packed); the other formats and
  // layouts in tests/inputs/test_pipewire_frame.cpp.
  const std::string small = " --signal sbs --profile " + test::q(test::write_small_profile(dir_));
  for (const auto& [format, ffmpeg_format] : {std::pair{"I420", "yuv420p"}, {"YUY2", "yuyv422"}}) {
    SCOPED_TRACE(format);
    const auto raw = dir_ / "bars.yuv", picture = dir_ / "bars.png", reference = dir_ / "reference.png";
    const auto made = test::run_command(fmt::format(
        "gst-launch-1.0 -q videotestsrc num-buffers=1 pattern=smpte ! video/x-raw,format={},width=640,height=180 ! "
        "filesink location={} && ffmpeg -v error -f rawvideo -pix_fmt {} -s 640x180 -i {} "
        "-sws_flags bicubic+accurate_rnd+full_chroma_int -pix_fmt rgb24 -y {}",
        format, test::q(raw), ffmpeg_format, test::q(raw), test::q(picture)));
    ASSERT_EQ(made.status, 0) << made.err;
    ASSERT_EQ(test::run_nelf("convert " + test::q(picture) + " -y " + test::q(reference) + small).status, 0);
    const std::string name = std::string("yuv-") + format;
    start_node(name, format);
    const auto out = dir_ / (name + ".png");
    const auto r = test::run_nelf("convert pipewire:node=" + name + " " + test::q(out) + " --frames 1" + small);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto got = test::read_back(out), expected = test::read_back(reference);
    ASSERT_EQ(got.width, expected.width);
    ASSERT_EQ(got.height, expected.height);
    EXPECT_EQ(differing_channels(got, expected), 0u);
  }
}

TEST_F(PipeWireCliTest, ARecordingEndsCompleteWhenTheNodeGoesAway) {
  // As a game's window closing ends `x11:window=`: the producer quits, nelf finishes the file.
  start_node("leaving", "BGRx");
  const auto out = dir_ / "recording.mkv";
  auto recording =
      std::async(std::launch::async, [&] { return test::run_nelf("convert pipewire:node=leaving " + test::q(out)); });
  std::this_thread::sleep_for(3s);
  nodes_.back()->stop();
  ASSERT_EQ(recording.wait_for(20s), std::future_status::ready) << "nelf went on after the node was gone";
  const auto r = recording.get();
  ASSERT_EQ(r.status, 0) << r.err;
  const auto probed = test::run_command(
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
      "stream=width,height,nb_read_frames -of csv=p=0 " +
      test::q(out));
  ASSERT_EQ(probed.status, 0) << probed.err;
  int width = 0, height = 0, frames = 0;
  ASSERT_EQ(std::sscanf(probed.out.c_str(), "%d,%d,%d", &width, &height, &frames), 3) << probed.out;
  EXPECT_EQ(width, 1280);
  EXPECT_EQ(height, 1470);
  EXPECT_GE(frames, 20) << "about 3 s at 30 fps were sent";
}

TEST_F(PipeWireCliTest, BadNodesAreOneLine) {
  start_node("bars", "BGRx");
  test::expect_clean_failure(dir_, "convert pipewire:node=bars,restore=no out.mkv --frames 1", 2,
                             "restore= is about the ScreenCast portal's kept choice");
  test::expect_clean_failure(dir_, "convert pipewire:restore=maybe out.mkv --frames 1", 2,
                             "restore=maybe is not yes or no");
  test::expect_clean_failure(dir_, "convert pipewire:node=bars,fps=0 out.mkv --frames 1", 2,
                             "fps=0 is not a rate from 1 to 1000 frames a second");
  test::expect_clean_failure(dir_, "convert pipewire:node=bars,colour=red out.mkv --frames 1", 2, "unknown key colour");
  test::expect_clean_failure(dir_, "convert pipewire:node=nosuch out.mkv --frames 1", 1,
                             "no PipeWire node nosuch; the video nodes: ");
  test::expect_clean_failure(dir_, "convert pipewire:node=nosuch out.mkv --frames 1", 1, "\"bars\" (Video/Source)");
  test::expect_clean_failure(dir_, "convert pipewire:node=bars out.mkv --frames 1 --layout alt", 2,
                             "layout alt needs a file");
  test::expect_clean_failure(dir_, "probe pipewire:node=bars", 2, "probe describes media files");
  start_node("grey", "GRAY8");
  test::expect_clean_failure(dir_, "convert pipewire:node=grey out.mkv --frames 1", 1,
                             "the link to the node failed (no more input formats); nelf reads 8-bit RGB frames");
  {
    const test::TempDir nowhere;
    const test::ScopedEnv no_daemon("PIPEWIRE_RUNTIME_DIR", nowhere.path().string());
    test::expect_clean_failure(dir_, "convert pipewire:node=bars out.mkv --frames 1", 1, "cannot connect to PipeWire");
  }
}

// A desktop session of its own: a session bus whose activated xdg-desktop-portal sees only the test
// backend (XDG_DESKTOP_PORTAL_DIR, XDG_CURRENT_DESKTOP), keeps its tokens under a private
// XDG_DATA_HOME, and WirePlumber to link what the portal's connection cannot.
class PortalCliTest : public PipeWireCliTest {
 protected:
  void SetUp() override {
    PipeWireCliTest::SetUp();
    if (HasFatalFailure()) return;
    const auto portals = desktop_ / "portals";
    std::filesystem::create_directories(portals);
    test::write_file(portals / "nelftest.portal",
                     "[portal]\nDBusName=org.freedesktop.impl.portal.desktop.nelftest\n"
                     "Interfaces=org.freedesktop.impl.portal.ScreenCast;\nUseIn=nelf-test\n");
    portal_dir_.emplace("XDG_DESKTOP_PORTAL_DIR", portals.string());
    bus_ = start_bus("bus", true);
    bus_address_.emplace("DBUS_SESSION_BUS_ADDRESS", "unix:path=" + (runtime_ / "bus").string());
    session_manager_ = std::make_unique<Background>(std::vector<std::string>{"wireplumber"});
  }

  // A dbus-daemon listening at RUNTIME/name; `services`: it activates what the system installs
  // (xdg-desktop-portal and its permission store), otherwise nothing.
  std::unique_ptr<Background> start_bus(const std::string& name, bool services) {
    const auto config = desktop_ / (name + ".conf");
    test::write_file(config,
                     fmt::format("<!DOCTYPE busconfig PUBLIC \"-//freedesktop//DTD D-Bus Bus Configuration 1.0//EN\" "
                                 "\"http://www.freedesktop.org/standards/dbus/1.0/busconfig.dtd\">\n"
                                 "<busconfig><type>session</type><listen>unix:path={}</listen>{}"
                                 "<policy context=\"default\"><allow send_destination=\"*\" eavesdrop=\"true\"/>"
                                 "<allow eavesdrop=\"true\"/><allow own=\"*\"/></policy></busconfig>\n",
                                 (runtime_ / name).string(), services ? "<standard_session_servicedirs/>" : ""));
    auto bus = std::make_unique<Background>(
        std::vector<std::string>{"dbus-daemon", "--nofork", "--config-file=" + config.string()});
    for (int i = 0; i < 300 && !std::filesystem::exists(runtime_ / name); ++i) std::this_thread::sleep_for(10ms);
    EXPECT_TRUE(std::filesystem::exists(runtime_ / name)) << "dbus-daemon did not start";
    return bus;
  }

  // The desktop's half of the portal; `answer`: accept, cancel or never (the dialog stays open).
  void start_backend(const std::string& answer) {
    backend_ = std::make_unique<Background>(std::vector<std::string>{
        NELF_TEST_SCREENCAST_BACKEND, "--node-file", (desktop_ / "node").string(), "--width", "640", "--height", "180",
        "--answer", answer, "--log", (desktop_ / "backend.log").string()});
    const auto ready = desktop_ / "backend.log.ready";
    std::filesystem::remove(ready);
    for (int i = 0; i < 300; ++i) {
      if (std::filesystem::exists(ready)) return;
      std::this_thread::sleep_for(20ms);
    }
    FAIL() << "the test backend did not take its name on the bus";
  }

  // A new node as the screen the next cast shows (a desktop makes a node per cast).
  void next_screen() {
    const std::string name = fmt::format("screen-{}", screens_++);
    start_node(name, "BGRx");
    const auto listed = test::run_command("pw-cli ls Node");
    const std::size_t at = listed.out.find("node.name = \"" + name + "\"");
    ASSERT_NE(at, std::string::npos);
    const std::size_t id = listed.out.rfind("\tid ", at);
    ASSERT_NE(id, std::string::npos);
    test::write_file(desktop_ / "node", std::to_string(std::stoul(listed.out.substr(id + 4))) + "\n");
  }

  std::string backend_log() const {
    std::string log = test::read_file(desktop_ / "backend.log");
    for (char& c : log)
      if (c == '\n') c = ' ';
    return log;
  }

  test::TempDir desktop_, data_, state_;
  test::ScopedEnv runtime_dir_{"XDG_RUNTIME_DIR", runtime_.path().string()};
  test::ScopedEnv desktop_name_{"XDG_CURRENT_DESKTOP", "nelf-test"};
  test::ScopedEnv data_home_{"XDG_DATA_HOME", data_.path().string()};
  test::ScopedEnv state_home_{"XDG_STATE_HOME", state_.path().string()};
  std::optional<test::ScopedEnv> portal_dir_, bus_address_;
  std::unique_ptr<Background> bus_, session_manager_, backend_;
  int screens_ = 0;
};

TEST_F(PortalCliTest, TheUserIsAskedOnceAndTheChoiceIsKept) {
  // What the portal casts is recorded as the same picture from a file would be; the portal's restore
  // token is kept under XDG_STATE_HOME, so the next run takes the choice back without a dialog, and
  // restore=no asks again.
  start_backend("accept");
  test::ReadBack expected;
  ASSERT_NO_FATAL_FAILURE(convert_bars_still(expected));
  next_screen();
  const auto out = dir_ / "cast.png";
  auto r = test::run_nelf("convert pipewire: " + test::q(out) + " --frames 1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the desktop's screen cast of a monitor (PipeWire node "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("640x180, live, two 320x180 views, layout sbs (aspect)"), std::string::npos) << r.err;
  const auto got = test::read_back(out);
  ASSERT_EQ(got.width, expected.width);
  ASSERT_EQ(got.height, expected.height);
  EXPECT_EQ(differing_channels(got, expected), 0u);
  EXPECT_EQ(backend_log(), "asked started closed ") << "the session is closed when nelf ends";
  EXPECT_TRUE(std::filesystem::exists(state_ / "nelf" / "screencast-restore-token"));

  next_screen();
  r = test::run_nelf("convert pipewire: " + test::q(dir_ / "again.png") + " --frames 1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(backend_log(), "asked started closed restored started closed ") << "the kept choice was not restored";

  next_screen();
  r = test::run_nelf("convert pipewire:restore=no " + test::q(dir_ / "ask.png") + " --frames 1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(backend_log(), "asked started closed restored started closed asked started closed ");
}

TEST_F(PortalCliTest, ARefusedOrMissingPortalIsOneLine) {
  start_backend("cancel");
  next_screen();
  test::expect_clean_failure(dir_, "convert pipewire: out.mkv --frames 1", 1,
                             "pipewire:: the screen cast was cancelled");
  EXPECT_FALSE(std::filesystem::exists(state_ / "nelf" / "screencast-restore-token"));
  {
    const auto bare = start_bus("bare-bus", false);
    const test::ScopedEnv bare_bus("DBUS_SESSION_BUS_ADDRESS", "unix:path=" + (runtime_ / "bare-bus").string());
    test::expect_clean_failure(dir_, "convert pipewire: out.mkv --frames 1", 1,
                               "no ScreenCast portal on the session bus");
  }
  {
    const test::ScopedEnv no_bus("DBUS_SESSION_BUS_ADDRESS", "unix:path=" + (runtime_ / "nothing-here").string());
    test::expect_clean_failure(dir_, "convert pipewire: out.mkv --frames 1", 1, "cannot reach the session bus");
  }
  {
    // The portal's connection sees only the cast's node: without a session manager nothing links it.
    session_manager_->stop();
    backend_.reset();
    start_backend("accept");
    next_screen();
    test::expect_clean_failure(dir_, "convert pipewire: out.mkv --frames 1", 1,
                               "nothing linked nelf to the cast's node in 10 s");
  }
}

TEST_F(PortalCliTest, CtrlCWhileTheDialogIsOpenEndsCleanly) {
  start_backend("never");
  next_screen();
  const auto out = dir_ / "out.mkv";
  const auto r = test::run_command(std::string(NELF_BINARY) + " convert pipewire: " + test::q(out) +
                                   " & pid=$!; sleep 2; kill -INT $pid; (sleep 20; kill -KILL $pid) 2>/dev/null & "
                                   "guard=$!; wait $pid; status=$?; kill $guard 2>/dev/null; exit $status");
  EXPECT_EQ(r.status, 130) << r.err;
  EXPECT_NE(r.err.find("pipewire:: interrupted"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace nelf
