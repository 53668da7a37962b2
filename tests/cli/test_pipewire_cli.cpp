// `pipewire:node=…` against a real PipeWire daemon and a real producer: each test starts its own
// daemon (`pipewire`, its socket in a private runtime directory that PIPEWIRE_RUNTIME_DIR names for
// every client) and GStreamer's videotestsrc into pipewiresink as the node, and stops them.
// GStreamer's pipewiresink (Debian 12) sends nothing more once its first reader has left, so each
// nelf run reads a node of its own.
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
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "support/image_files.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using namespace std::chrono_literals;

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
        width, height, test::shell_quote(raw.string()), width, height, test::shell_quote(raw.string()),
        test::shell_quote(png.string())));
    EXPECT_EQ(made.status, 0) << made.err;
    std::filesystem::remove(raw);
    return png;
  }

  test::TempDir dir_, runtime_;
  test::ScopedEnv remote_{"PIPEWIRE_RUNTIME_DIR", runtime_.path().string()};
  std::unique_ptr<Background> daemon_;
  std::vector<std::unique_ptr<Background>> nodes_;
};

TEST_F(PipeWireCliTest, ANodesFramesAreWhatTheSameStillWouldShow) {
  // Two pixel orders a producer may send (BGRx as Wayland compositors do, RGBx): the frame nelf
  // records from the node is the frame it makes of the same picture as a file.
  const auto still = bars_still();
  const auto reference = dir_ / "reference.png";
  ASSERT_EQ(test::run_nelf("convert " + test::shell_quote(still.string()) + " " + test::shell_quote(reference.string()))
                .status,
            0);
  const auto expected = test::read_back(reference);
  for (const std::string format : {"BGRx", "RGBx"}) {
    SCOPED_TRACE(format);
    const std::string name = "bars-" + format;
    start_node(name, format);
    const auto out = dir_ / (name + ".png");
    const auto r =
        test::run_nelf("convert pipewire:node=" + name + " " + test::shell_quote(out.string()) + " --frames 1");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("\"" + name + "\" (Video/Source), 640x180, live, two 320x180 views, layout sbs (aspect)"),
              std::string::npos)
        << r.err;
    const auto got = test::read_back(out);
    ASSERT_EQ(got.width, expected.width);
    ASSERT_EQ(got.height, expected.height);
    std::size_t differing = 0;
    for (std::size_t i = 0; i < got.pixels.size(); ++i)
      if (std::abs(got.pixels[i] - expected.pixels[i]) > 2.5f / 255) ++differing;
    EXPECT_EQ(differing, 0u);
  }
}

TEST_F(PipeWireCliTest, ARecordingEndsCompleteWhenTheNodeGoesAway) {
  // As a game's window closing ends `x11:window=`: the producer quits, nelf finishes the file.
  start_node("leaving", "BGRx");
  const auto out = dir_ / "recording.mkv";
  auto recording = std::async(std::launch::async, [&] {
    return test::run_nelf("convert pipewire:node=leaving " + test::shell_quote(out.string()));
  });
  std::this_thread::sleep_for(3s);
  nodes_.back()->stop();
  ASSERT_EQ(recording.wait_for(20s), std::future_status::ready) << "nelf went on after the node was gone";
  const auto r = recording.get();
  ASSERT_EQ(r.status, 0) << r.err;
  const auto probed = test::run_command(
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
      "stream=width,height,nb_read_frames -of csv=p=0 " +
      test::shell_quote(out.string()));
  ASSERT_EQ(probed.status, 0) << probed.err;
  int width = 0, height = 0, frames = 0;
  ASSERT_EQ(std::sscanf(probed.out.c_str(), "%d,%d,%d", &width, &height, &frames), 3) << probed.out;
  EXPECT_EQ(width, 1280);
  EXPECT_EQ(height, 1470);
  EXPECT_GE(frames, 20) << "about 3 s at 30 fps were sent";
}

TEST_F(PipeWireCliTest, BadNodesAreOneLine) {
  start_node("bars", "BGRx");
  test::expect_clean_failure(dir_, "convert pipewire: out.mkv --frames 1", 2,
                             "name the node: pipewire:node=ID or NAME (pw-cli ls Node lists them)");
  test::expect_clean_failure(dir_, "convert pipewire:node=bars,fps=0 out.mkv --frames 1", 2,
                             "fps=0 is not a rate from 1 to 1000 frames a second");
  test::expect_clean_failure(dir_, "convert pipewire:node=bars,colour=red out.mkv --frames 1", 2, "unknown key colour");
  test::expect_clean_failure(dir_, "convert pipewire:node=nosuch out.mkv --frames 1", 1,
                             "no PipeWire node nosuch; the video nodes: ");
  test::expect_clean_failure(dir_, "convert pipewire:node=nosuch out.mkv --frames 1", 1, "\"bars\" (Video/Source)");
  test::expect_clean_failure(dir_, "convert pipewire:node=bars out.mkv --frames 1 --layout alt", 2,
                             "layout alt needs a file");
  test::expect_clean_failure(dir_, "probe pipewire:node=bars", 2, "probe describes media files");
  start_node("yuv", "I420");
  test::expect_clean_failure(dir_, "convert pipewire:node=yuv out.mkv --frames 1", 1,
                             "the link to the node failed (no more input formats); nelf reads 8-bit RGB frames");
  {
    const test::TempDir nowhere;
    const test::ScopedEnv no_daemon("PIPEWIRE_RUNTIME_DIR", nowhere.path().string());
    test::expect_clean_failure(dir_, "convert pipewire:node=bars out.mkv --frames 1", 1, "cannot connect to PipeWire");
  }
}

}  // namespace
}  // namespace nelf
