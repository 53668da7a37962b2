// The player engine on a real window (private Xvfb): what only a window does. Closing it ends play;
// what the player renders reaches the window. What play does with frames, keys and the compositor's
// paths is tested on the offscreen output (tests/player/gl).
#include <gtest/gtest.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "compositor/gl/gl_compositor.hpp"
#include "hmz_output/packing.hpp"
#include "hmz_output/window_display.hpp"
#include "inputs/source_drivers.hpp"
#include "player/player.hpp"
#include "support/image_files.hpp"
#include "support/player_tests.hpp"
#include "support/test_support.hpp"
#include "support/x11_window.hpp"
#include "support/xvfb.hpp"

namespace nelf {
namespace {

using test::make_clip;
using test::Mean;
using test::mean_of;

class PlayerWindowTest : public ::testing::Test {
 protected:
  test::XvfbServer xvfb_;
  test::ScopedDisplay display_env_{xvfb_.display_name()};
  test::TempDir dir_;

  PlayerOptions silent_options() const { return test::silent_options(dir_); }
  // A window showing the packed frame of `options`' 160x90 panel.
  static std::unique_ptr<Display> open_display(const PlayerOptions& options) {
    return open_window_display(test::small_panel_display_options(options), WindowMode::window);
  }
};

TEST_F(PlayerWindowTest, ClosingTheWindowEndsPlaybackCleanly) {
  const auto clip = make_clip(dir_);
  PlayerOptions options = silent_options();
  auto display = open_display(options);
  int rendered = 0;
  // What the window manager's close button does to a GLFW window.
  options.after_render = [&](const Display&, double) {
    if (++rendered == 3) glfwSetWindowShouldClose(glfwGetCurrentContext(), GLFW_TRUE);
  };
  auto source = open_source(SourceRequest{clip.string(), "", std::nullopt, false, std::nullopt, true, false});
  const PlayResult result = play(*display, *source, options);
  EXPECT_EQ(result.end, PlayEnd::window_closed);
  EXPECT_EQ(result.counters.shown, 3);
}

// An on-screen message is also a flat caption over the preview window (bright text on a dark box
// across its bottom centre), where the copies drawn into the views are too small to read.
TEST_F(PlayerWindowTest, AMessageIsACaptionOverThePreviewWindowOnly) {
  const auto clip = make_clip(dir_);
  std::vector<test::WindowCapture> windows;
  int packed_white_below = 0;
  const auto played = [&](const std::string& announce) {
    PlayerOptions options = silent_options();
    options.announce = announce;
    auto display = open_display(options);
    int rendered = 0;
    options.after_render = [&](const Display& d, double) {
      if (++rendered != 3) return;
      windows.push_back(test::capture_window(glfwGetCurrentContext()));  // frame 2, as presented
      const auto [w, h] = d.packed_size();
      const Image below = read_back(d.packed_framebuffer(), 0, h * 5 / 6, w, h - h * 5 / 6);
      for (std::size_t i = 0; i < static_cast<std::size_t>(below.width()) * below.height(); ++i)
        packed_white_below += below.data()[i * 4] > 0.8f && below.data()[i * 4 + 1] > 0.8f;
    };
    auto source = open_source(SourceRequest{clip.string(), "", std::nullopt, false, std::nullopt, true, false});
    EXPECT_EQ(play(*display, *source, options).end, PlayEnd::end_of_file);
  };
  played("");
  played("PREVIEW CAPTION");
  ASSERT_EQ(windows.size(), 2u);
  const test::WindowCapture &plain = windows[0], &captioned = windows[1];
  ASSERT_EQ(plain.width, captioned.width);
  ASSERT_EQ(plain.height, captioned.height);
  // Near-white pixels in the middle half of the window's width, rows [y0, y1).
  const auto white_pixels = [](const test::WindowCapture& window, int y0, int y1) {
    int n = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = window.width / 4; x < window.width * 3 / 4; ++x) {
        const auto c = window.at(x, y);
        n += c[0] > 200 && c[1] > 200 && c[2] > 200;
      }
    return n;
  };
  // Below the panels the packed frame is black: there the caption's letters are the only white.
  const int low = plain.height * 5 / 6;
  EXPECT_EQ(white_pixels(plain, low, plain.height), 0);
  EXPECT_GT(white_pixels(captioned, low, plain.height), 200);
  // The packed frame itself (what the HMD is sent, what Ctrl+s saves) has no caption.
  EXPECT_EQ(packed_white_below, 0);
}

// A stereo photo plays as its one frame (for --image-duration), read as convert reads it (the still driver): a JPS
// (right view first) and an MPO (two JPEGs) both show the left view to the left eye, in the window too.
TEST_F(PlayerWindowTest, AStereoPhotoShowsEachEyesView) {
  const Image red = test::filled_image(320, 180, {0.75f, 0.2f, 0.1f, 1.f});
  const Image blue = test::filled_image(320, 180, {0.1f, 0.25f, 0.75f, 1.f});
  Image jps(640, 180);
  for (int y = 0; y < 180; ++y)
    for (int x = 0; x < 320; ++x) {
      jps.at(x, y) = blue.at(x, y);
      jps.at(320 + x, y) = red.at(x, y);
    }
  test::write_test_image(dir_ / "photo.jps", jps, 3, OIIO::TypeDesc::UINT8, "jpeg");
  test::write_test_image(dir_ / "l.jpg", red, 3, OIIO::TypeDesc::UINT8, "jpeg");
  test::write_test_image(dir_ / "r.jpg", blue, 3, OIIO::TypeDesc::UINT8, "jpeg");
  test::write_file(dir_ / "camera.mpo", test::read_file(dir_ / "l.jpg") + test::read_file(dir_ / "r.jpg"));

  PlayerOptions options = silent_options();
  options.image_duration_s = 0.1;  // else a photo stays until a key
  auto display = open_display(options);
  const auto left = *eye_area(options.signal, Eye::left, 160, 90);
  const auto right = *eye_area(options.signal, Eye::right, 160, 90);
  for (const char* name : {"photo.jps", "camera.mpo"}) {
    SCOPED_TRACE(name);
    std::vector<std::pair<Mean, Mean>> seen;
    options.after_render = [&](const Display& d, double pts) {
      EXPECT_EQ(pts, 0.0);
      const auto panel = [&](const EyeArea& a) {
        return mean_of(
            read_back(d.packed_framebuffer(), a.x + (a.width - 160) / 2, a.y + (a.height - 90) / 2, 160, 90));
      };
      seen.emplace_back(panel(left), panel(right));
    };
    auto source =
        open_source(SourceRequest{(dir_ / name).string(), "", std::nullopt, false, std::nullopt, true, false});
    EXPECT_NE(source->info().description.find("still image"), std::string::npos) << source->info().description;
    const PlayResult result = play(*display, *source, options);
    EXPECT_EQ(result.end, PlayEnd::end_of_file);
    EXPECT_EQ(result.counters.shown, 1);
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_GT(seen[0].first.r, seen[0].first.b + 0.2);
    EXPECT_GT(seen[0].second.b, seen[0].second.r + 0.2);
    // And the window shows that frame (1:1: the screen has room for it), as the X server draws it.
    const test::WindowCapture screen = test::capture_window(glfwGetCurrentContext());
    ASSERT_EQ(screen.width, 1280);
    ASSERT_EQ(screen.height, 1470);
    const auto centre = [&](const EyeArea& a) { return screen.at(a.x + a.width / 2, a.y + a.height / 2); };
    EXPECT_GT(centre(left)[0], centre(left)[2] + 50);
    EXPECT_GT(centre(right)[2], centre(right)[0] + 50);
  }
}

}  // namespace
}  // namespace nelf
