// `nelf calibrate` in a window on a private Xvfb server, driven as a user would: synthetic key
// presses (xdotool) change what --save writes, exactly as the keys say, and the saved profile works
// with `nelf convert` and `nelf calibrate --profile`.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "optics/defect_map.hpp"
#include "optics/mapping.hpp"
#include "optics/profile.hpp"
#include "support/image_files.hpp"
#include "support/test_support.hpp"
#include "support/x11_close_window.hpp"
#include "support/xvfb.hpp"

namespace nelf {
namespace {

using test::run_command;
using test::q;
using test::shell_quote;
using test::TempDir;

// `nelf ARGS` running in the background (its stdout and stderr in files); killed if still running
// when destroyed.
class NelfProcess {
 public:
  NelfProcess(const std::string& args, const std::filesystem::path& out, const std::filesystem::path& err) {
    const std::string command = "exec " + shell_quote(NELF_BINARY) + " " + args + " >" + q(out) + " 2>" + q(err);
    pid_ = fork();
    if (pid_ == 0) {
      execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
  }
  ~NelfProcess() {
    if (pid_ > 0 && !status_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  NelfProcess(const NelfProcess&) = delete;
  NelfProcess& operator=(const NelfProcess&) = delete;

  pid_t pid() const { return pid_; }

  // The exit status (128 + signal when killed), or nothing when it still runs after `timeout`.
  std::optional<int> wait(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (!status_) {
      int raw = 0;
      const pid_t r = waitpid(pid_, &raw, WNOHANG);
      if (r == pid_)
        status_ = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
      else if (std::chrono::steady_clock::now() > end)
        break;
      else
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return status_;
  }

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
};

class CalibrateWindowTest : public ::testing::Test {
 protected:
  // The calibrate window of `process`, waiting (up to 30 s: llvmpipe compiles the shaders) until
  // it is mapped. Empty when it never appeared.
  std::string find_window(const NelfProcess& process) {
    const auto r = run_command(fmt::format("timeout 30 xdotool search --sync --onlyvisible --all --pid {} --name {}",
                                           process.pid(), shell_quote("^nelf calibrate")));
    return r.out.substr(0, r.out.find('\n'));
  }
  // Types `keys` into `window`. When that fails, says why the window is gone: nelf ended (its
  // status and stderr), or the test's X server did.
  void keys(NelfProcess& nelf, const std::string& window, const std::string& keys) {
    const auto r = run_command("xdotool key --delay 5 --window " + window + " " + keys);
    if (r.status == 0) return;
    const std::optional<int> status = nelf.wait(std::chrono::milliseconds(0));
    FAIL() << r.err << "nelf " << (status ? "ended with status " + std::to_string(*status) : std::string("still runs"))
           << "; the test's Xvfb " << (xvfb_.running() ? "still runs" : "has ended")
           << "; nelf said: " << test::read_file(dir_ / "err.txt");
  }

  test::XvfbServer xvfb_;
  test::ScopedDisplay display_env_{xvfb_.display_name()};
  TempDir dir_;
};

TEST_F(CalibrateWindowTest, KeysChangeWhatSaveWrites) {
  const auto saved = dir_ / "mine.toml";
  NelfProcess nelf("calibrate --save " + q(saved), dir_ / "out.txt", dir_ / "err.txt");
  const std::string window = find_window(nelf);
  ASSERT_FALSE(window.empty()) << test::read_file(dir_ / "err.txt");
  // Both eyes 2 px right; the left eye rotated +0.1 deg and 0.1 px up; the right eye 1 px left;
  // then both eyes: IPD +0.5 mm, prescription -0.25 D, gap +0.005 mm, pitch scale +0.0005; quit.
  keys(nelf, window, "Right Right Tab R R shift+Up Tab Left Tab bracketright d G P 3 2 q");
  const auto status = nelf.wait(std::chrono::seconds(30));
  ASSERT_TRUE(status) << "nelf calibrate did not quit on q";
  const std::string out = test::read_file(dir_ / "out.txt");
  EXPECT_EQ(*status, 0) << out << test::read_file(dir_ / "err.txt");
  EXPECT_NE(out.find("saved " + saved.string()), std::string::npos) << out;
  EXPECT_EQ(test::read_file(dir_ / "err.txt"), "");

  const Profile p = load_profile(saved.string());
  const Profile start = load_profile("hmz-t1");
  // The saved file is a profile of its own, named after the file, not the built-in it started from.
  EXPECT_EQ(p.name, "mine");
  EXPECT_EQ(p.eye_calibration(Eye::left).shift_px, (Vec2{2.0, -0.1}));
  EXPECT_EQ(p.eye_calibration(Eye::left).rotation_deg, 0.1);
  EXPECT_EQ(p.eye_calibration(Eye::left).pitch_scale, 1.0005);
  EXPECT_EQ(p.eye_calibration(Eye::right).shift_px, (Vec2{1.0, 0.0}));
  EXPECT_EQ(p.eye_calibration(Eye::right).rotation_deg, 0.0);
  EXPECT_EQ(p.eye_calibration(Eye::right).pitch_scale, 1.0005);
  EXPECT_EQ(p.viewing.ipd_mm, 63.5);
  EXPECT_EQ(p.correction.prescription_diopters, -0.25);
  ASSERT_TRUE(p.lens_array->gap_mm);
  EXPECT_NEAR(*p.lens_array->gap_mm, lens_gap_mm(start) + 0.005, 1e-6);

  // The saved profile is a profile like any other: convert and calibrate accept it.
  test::write_test_image(dir_ / "sbs.png", test::filled_image(128, 36, Rgba{0.8f, 0.5f, 0.2f, 1.f}), 3);
  auto r = run_command(shell_quote(NELF_BINARY) + " convert --profile " + q(saved) + " " + q(dir_ / "sbs.png") + " " +
                       q(dir_ / "packed.png"));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(test::read_back(dir_ / "packed.png").height, 1470);
  r = run_command(shell_quote(NELF_BINARY) + " calibrate --pattern grid --profile " + q(saved) + " --output " +
                  q(dir_ / "grid.png"));
  EXPECT_EQ(r.status, 0) << r.err;
}

TEST_F(CalibrateWindowTest, WritesOnWAndStartsFromTheGivenProfile) {
  // Start from a saved profile and save over it with w while running, then end with SIGINT, which
  // saves again and exits cleanly.
  const auto saved = dir_ / "again.toml";
  Profile start = load_profile("hmz-t1");
  start.viewing.ipd_mm = 60.0;
  test::write_file(saved, profile_to_toml(start));
  NelfProcess nelf("calibrate --pattern grid --profile " + q(saved) + " --save " + q(saved), dir_ / "out.txt",
                   dir_ / "err.txt");
  const std::string window = find_window(nelf);
  ASSERT_FALSE(window.empty()) << test::read_file(dir_ / "err.txt");
  keys(nelf, window, "bracketleft w");
  // w saves while the window stays open.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (load_profile(saved.string()).viewing.ipd_mm != 59.5 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(load_profile(saved.string()).viewing.ipd_mm, 59.5);
  EXPECT_FALSE(nelf.wait(std::chrono::milliseconds(0)));
  // Ctrl-C in the terminal: a clean exit that saves once more.
  kill(nelf.pid(), SIGINT);
  const auto status = nelf.wait(std::chrono::seconds(20));
  ASSERT_TRUE(status);
  EXPECT_EQ(*status, 0) << test::read_file(dir_ / "err.txt");
  const std::string out = test::read_file(dir_ / "out.txt");
  const std::string line = "saved " + saved.string() + "\n";
  const auto first = out.find(line);
  ASSERT_NE(first, std::string::npos) << out;
  EXPECT_NE(out.find(line, first + 1), std::string::npos) << out;
  EXPECT_EQ(load_profile(saved.string()).viewing.ipd_mm, 59.5);
}

TEST_F(CalibrateWindowTest, TheWindowShowsWhatTheHeadlessPatternWrites) {
  // The interactive path (pattern textures, render_eye into the display's packed framebuffer at
  // the eye areas) and the headless one (compose, pack_eyes, image file) give the same frame.
  NelfProcess nelf("calibrate --pattern grid", dir_ / "out.txt", dir_ / "err.txt");
  const std::string window = find_window(nelf);
  ASSERT_FALSE(window.empty()) << test::read_file(dir_ / "err.txt");
  // Where the window is and how big, polled until it has its final 1:1 size (the 1920x1600
  // screen holds the packed frame 1:1): a loaded X server may answer before the resize lands.
  int x = -1, y = -1, width = 0, height = 0;
  std::string geometry;
  for (const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);;) {
    geometry = run_command("xdotool getwindowgeometry --shell " + window).out;
    for (const auto& [key, value] : {std::pair{"X=", &x}, {"Y=", &y}, {"WIDTH=", &width}, {"HEIGHT=", &height}}) {
      const auto at = geometry.find(std::string("\n") + key);
      ASSERT_NE(at, std::string::npos) << geometry;
      *value = std::stoi(geometry.substr(at + 1 + std::string(key).size()));
    }
    if ((width == 1280 && height == 1470) || std::chrono::steady_clock::now() > deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_EQ(width, 1280) << geometry;
  ASSERT_EQ(height, 1470) << geometry;
  const auto written = dir_ / "written.png";
  auto r = run_command(shell_quote(NELF_BINARY) + " calibrate --pattern grid --output " + q(written));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto b = test::read_back(written);
  ASSERT_EQ(b.width, width);
  ASSERT_EQ(b.height, height);

  // The start message ("h: keys  q: quit") is on screen for 2.5 s, and a capture may catch a
  // frame half put into the window; capture until one matches, giving a loaded machine 30 s.
  const auto shown = dir_ / "shown.png";
  double difference = 1.0, lit = 0.0, gap = 1.0;
  const double pixels = 3.0 * width * height;
  int captures = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  while ((difference >= 2.0 / 255 || gap > 0) && std::chrono::steady_clock::now() < deadline) {
    std::filesystem::remove(shown);
    r = run_command(
        fmt::format("ffmpeg -loglevel error -f x11grab -draw_mouse 0 -video_size {}x{} -i {}+{},{} -frames:v 1 {}",
                    width, height, xvfb_.display_name(), x, y, q(shown)));
    ASSERT_EQ(r.status, 0) << r.err;
    ++captures;
    const auto a = test::read_back(shown);
    ASSERT_EQ(a.width, width);
    ASSERT_EQ(a.height, height);
    difference = lit = gap = 0.0;
    for (int yy = 0; yy < a.height; ++yy)
      for (int xx = 0; xx < a.width; ++xx)
        for (int c = 0; c < 3; ++c) {
          difference += std::abs(a.at(xx, yy, c) - b.at(xx, yy, c));
          lit += b.at(xx, yy, c);
          if (yy >= 720 && yy < 750) gap += a.at(xx, yy, c);  // the gap rows stay black in the window too
        }
    difference /= pixels;
    if (difference >= 2.0 / 255 || gap > 0) std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  keys(nelf, window, "q");
  ASSERT_TRUE(nelf.wait(std::chrono::seconds(20)));
  const std::string why = fmt::format("after {} captures of {}x{} at {},{}; nelf said: {}", captures, width, height, x,
                                      y, test::read_file(dir_ / "err.txt"));
  EXPECT_GT(lit / pixels, 0.05) << why;     // there is a pattern to compare
  EXPECT_LT(difference, 2.0 / 255) << why;  // 8-bit view textures in the window, 16-bit float headless
  EXPECT_EQ(gap, 0.0) << why;
}

TEST_F(CalibrateWindowTest, ClosingTheWindowSavesAndExitsCleanly) {
  const auto saved = dir_ / "closed.toml";
  NelfProcess nelf("calibrate --save " + q(saved), dir_ / "out.txt", dir_ / "err.txt");
  const std::string window = find_window(nelf);
  ASSERT_FALSE(window.empty()) << test::read_file(dir_ / "err.txt");
  keys(nelf, window, "D D");
  // The keys are queued before the close request, so they are handled first.
  test::request_window_close(xvfb_.display_name(), window);
  const auto status = nelf.wait(std::chrono::seconds(20));
  ASSERT_TRUE(status) << "nelf calibrate did not end when its window was closed";
  EXPECT_EQ(*status, 0) << test::read_file(dir_ / "err.txt");
  EXPECT_EQ(load_profile(saved.string()).correction.prescription_diopters, 0.5);
}

TEST_F(CalibrateWindowTest, DefectsKeysMarkPixelsAndSaveTheMapBesideTheProfile) {
  // --defects from the built-in (no map named): the marks go to mine.defects beside --save
  // mine.toml, which names it. The cursor starts at the centre of the left panel (640, 360).
  const auto saved = dir_ / "mine.toml";
  NelfProcess nelf("calibrate --defects --save " + q(saved), dir_ / "out.txt", dir_ / "err.txt");
  const std::string window = find_window(nelf);
  ASSERT_FALSE(window.empty()) << test::read_file(dir_ / "err.txt");
  // Left (640, 360) dead; 11 px right on the white field stuck white; the right eye 100 px up and
  // 1 left on the green field (space: white -> red -> green) stuck green; one more right, dead,
  // then unmarked with Backspace; a pixel on the left eye marked and unmarked with u; w; q.
  keys(nelf, window, "d Right shift+Right 2 s Tab ctrl+Up Left space space s Right d BackSpace Tab Down d u w q");
  const auto status = nelf.wait(std::chrono::seconds(30));
  ASSERT_TRUE(status) << "nelf calibrate --defects did not quit on q";
  const std::string out = test::read_file(dir_ / "out.txt");
  EXPECT_EQ(*status, 0) << out << test::read_file(dir_ / "err.txt");
  EXPECT_EQ(test::read_file(dir_ / "err.txt"), "");
  EXPECT_NE(out.find("nelf calibrate: marked left 640 360 dead (1 defect)\n"), std::string::npos) << out;
  EXPECT_NE(out.find("nelf calibrate: unmarked right 640 260 dead (3 defects)\n"), std::string::npos) << out;
  const std::string line =
      fmt::format("saved 3 defects to {} and {} naming it\n", (dir_ / "mine.defects").string(), saved.string());
  const auto first = out.find(line);
  ASSERT_NE(first, std::string::npos) << out;
  EXPECT_NE(out.find(line, first + 1), std::string::npos) << "w and the quit both save: " << out;

  EXPECT_EQ(test::read_file(dir_ / "mine.defects"),
            "# nelf defect map: EYE COLUMN ROW dead | EYE COLUMN ROW stuck R G B (row 0 the top; docs/defects.md)\n"
            "left 640 360 dead\n"
            "left 651 360 stuck 255 255 255\n"
            "right 639 260 stuck 0 255 0\n");
  const Profile p = load_profile(saved.string());
  EXPECT_EQ(p.name, "mine");
  EXPECT_EQ(p.correction.defect_map, "mine.defects");
  ASSERT_TRUE(p.correction.defects);
  EXPECT_EQ(p.correction.defects->defects.size(), 3u);
}

TEST(CalibrateWindowErrors, NoDisplayIsOneLineAndNothingSaved) {
  TempDir dir;
  test::ScopedDisplay no_display("");
  const auto r = run_command(shell_quote(NELF_BINARY) + " calibrate --save " + q(dir / "x.toml"));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("DISPLAY"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.toml"));
}

TEST(CalibrateWindowErrors, BadSavePathIsRefusedBeforeOpeningAWindow) {
  TempDir dir;
  test::ScopedDisplay no_display("");  // would fail later; the --save check comes first
  auto r = run_command(shell_quote(NELF_BINARY) + " calibrate --save " + q(dir / "missing" / "x.toml"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
  r = run_command(shell_quote(NELF_BINARY) + " calibrate --save " + q(dir / "x.txt"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("a profile is a .toml file"), std::string::npos) << r.err;
  // KMS: the KMS display's own one-line error, through calibrate (a missing device here, so that
  // the test behaves the same on machines with a GPU).
  r = run_command("NELF_DRM_DEVICE=/nonexistent/card9 " + shell_quote(NELF_BINARY) + " calibrate --output kms");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err,
            "nelf: NELF_DRM_DEVICE=/nonexistent/card9: no such device; set NELF_DRM_DEVICE to a card node such as "
            "/dev/dri/card0, or unset it\n");
}

}  // namespace
}  // namespace nelf
