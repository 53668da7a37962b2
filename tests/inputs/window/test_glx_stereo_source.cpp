// The glx-stereo: source against the test game in quad-buffer mode on a private Xvfb with Mesa, which
// has no stereo visuals: without nelf's interposer the game cannot open its window; with it
// (LD_PRELOAD, as `nelf run` starts games) both eyes arrive, each its own, frame after frame,
// through GLFW and through SDL2. A game that draws one picture gives that picture's views the same
// way; one that never swaps is said.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/frame_stamp.hpp"
#include "game/hud.hpp"
#include "game/planes_scene.hpp"
#include "inputs/glx_stereo_protocol.hpp"
#include "inputs/glx_stereo_source.hpp"
#include "inputs/source_drivers.hpp"
#include "support/source_requests.hpp"
#include "support/test_game.hpp"
#include "support/test_support.hpp"
#include "support/xvfb.hpp"

namespace nelf {
namespace {

using test::quiet_request;

class GlxStereoSourceTest : public ::testing::Test {
 protected:
  std::string socket() const { return (dir_.path() / "game.sock").string(); }
  std::vector<std::string> interposed() const {
    return {"LD_PRELOAD=" + glx_stereo_library_path(), std::string(glx_stereo::kSocketVariable) + "=" + socket()};
  }

  test::XvfbServer xvfb_;
  test::ScopedDisplay display_env_{xvfb_.display_name()};
  test::TempDir dir_;
};

TEST_F(GlxStereoSourceTest, MesaHasNoStereoVisualsForTheGameWithoutTheInterposer) {
  for (const char* toolkit : {"glfw", "sdl2"}) {
    SCOPED_TRACE(toolkit);
    test::TestGame game({"--toolkit", toolkit, "--mode", "quad-buffer", "--size", "320x180", "--frames", "3"});
    ASSERT_TRUE(game.wait_exit(std::chrono::seconds(20)));
    EXPECT_EQ(game.status(), 1);  // "cannot open … with stereo buffers" / "Couldn't find matching GLX visual"
  }
}

TEST_F(GlxStereoSourceTest, AQuadBufferGameGivesBothEyesFrameAfterFrame) {
  for (const char* toolkit : {"glfw", "sdl2"}) {
    SCOPED_TRACE(toolkit);
    test::TestGame game({"--toolkit", toolkit, "--mode", "quad-buffer", "--size", "320x180", "--fps", "30"},
                        interposed());
    auto source = open_source(quiet_request("glx-stereo:wait=20,socket=" + socket()));
    const SourceInfo info = source->info();
    EXPECT_TRUE(info.live);
    EXPECT_FALSE(info.seekable);
    EXPECT_EQ(info.view.width, 320);
    EXPECT_EQ(info.view.height, 180);
    std::optional<std::uint32_t> last;
    int stamped = 0;
    for (int i = 0; i < 12; ++i) {
      const std::optional<StereoVideoFrame> f = source->next();
      ASSERT_TRUE(f);
      ASSERT_EQ(f->width, 320);
      ASSERT_EQ(f->height, 180);
      EXPECT_GT(f->captured_ns, 0);
      // Each eye is its own: the bars stand at opposite disparities, so the views differ.
      EXPECT_NE(f->left, f->right);
      test::expect_game_background_below_the_bars(f->left, f->width, f->height);
      test::expect_game_background_below_the_bars(f->right, f->width, f->height);
      // Both eyes carry the same frame's stamp, upright (a flipped view reads as no stamp).
      const auto left = read_frame_stamp(f->left.data(), f->width, f->height, f->bits);
      const auto right = read_frame_stamp(f->right.data(), f->width, f->height, f->bits);
      ASSERT_TRUE(left && right) << "frame " << i;
      EXPECT_EQ(*left, *right);
      if (last) {
        EXPECT_GT(left->frame, *last);  // the newest frame each time, never one again
      }
      last = left->frame;
      ++stamped;
    }
    EXPECT_EQ(stamped, 12);
  }
}

TEST_F(GlxStereoSourceTest, SwapEyesSwapsTheGamesEyes) {
  test::TestGame game({"--mode", "quad-buffer", "--size", "320x180", "--fps", "30"}, interposed());
  SourceRequest request = quiet_request("glx-stereo:wait=20,socket=" + socket());
  request.swap_eyes = true;
  auto swapped = open_source(request);
  const std::optional<StereoVideoFrame> a = swapped->next();
  ASSERT_TRUE(a);
  // The bars of the left eye (eye_sign -1) stand left of the right eye's: the near bar's orange
  // begins further left in the left eye. Here the views are swapped, so the first view's begins
  // further right.
  const auto first_orange = [](const std::vector<std::uint8_t>& view, int width, int row) {
    for (int x = 0; x < width; ++x) {
      const std::uint8_t* p = &view[(static_cast<std::size_t>(row) * width + x) * 4];
      if (p[0] > 200 && p[1] > 80 && p[1] < 150 && p[2] < 90) return x;
    }
    return -1;
  };
  const int row = 90;  // the near bar spans rows 60..120 of 180
  const int first = first_orange(a->left, a->width, row), second = first_orange(a->right, a->width, row);
  ASSERT_GE(first, 0);
  ASSERT_GE(second, 0);
  EXPECT_GT(first, second);
}

// Where the left camera of the test game's planes scene shows the point (x, 0, z): the view's column.
double planes_left_column(int width, double x, double z) {
  using namespace test_game;
  const double camera_x = -kEyeSeparation / 2;
  const double ndc = ((x - camera_x) / z + camera_x / kConvergence) / half_fov_tangent();
  return (ndc + 1) / 2 * width;
}

TEST_F(GlxStereoSourceTest, TheGamesDepthBuffersGiveTheDisparityItsCamerasMake) {
  // `--depth auto`: the source asks the interposer for the depth buffers and relates them to the
  // views; the disparity of each plane is what the game's two cameras give it (planes_scene.hpp).
  for (const char* toolkit : {"glfw", "sdl2"}) {
    SCOPED_TRACE(toolkit);
    test::TestGame game(
        {"--toolkit", toolkit, "--mode", "quad-buffer", "--scene", "planes", "--size", "320x180", "--fps", "30"},
        interposed());
    SourceRequest request = quiet_request("glx-stereo:wait=20,socket=" + socket());
    request.known_depth = true;
    auto source = open_source(request);
    std::shared_ptr<const StereoDisparity> d;
    for (int i = 0; i < 30 && !d; ++i) {
      const std::optional<StereoVideoFrame> f = source->next();
      ASSERT_TRUE(f);
      d = f->disparity;
    }
    ASSERT_TRUE(d) << "no frame with the game's depth in 30";
    EXPECT_EQ(d->origin, DisparityOrigin::game);
    ASSERT_EQ(d->left.width, 320);
    ASSERT_EQ(d->left.height, 180);
    using namespace test_game;
    const double near_expected = planes_disparity(320, kNearPlane), far_expected = planes_disparity(320, kFarPlane);
    const int row = 90;  // the view's middle row: both planes
    const int near_x = static_cast<int>(planes_left_column(320, (kNearLeft + kNearRight) / 2, kNearPlane));
    const int far_x = static_cast<int>(planes_left_column(320, 0.6, kFarPlane));
    EXPECT_NEAR(d->left.d[row * 320 + near_x], near_expected, 0.5);
    EXPECT_NEAR(d->left.d[row * 320 + far_x], far_expected, 0.5);
    // The right view: the same plane's pixel is d to the left of the left view's.
    EXPECT_NEAR(d->right.d[row * 320 + near_x - static_cast<int>(std::lround(near_expected))], near_expected, 0.5);
    EXPECT_NEAR(d->right.d[row * 320 + far_x], far_expected, 0.5);
  }
}

TEST_F(GlxStereoSourceTest, WithoutDepthAskedForTheFramesCarryNone) {
  test::TestGame game({"--mode", "quad-buffer", "--scene", "planes", "--size", "320x180", "--fps", "30"}, interposed());
  auto source = open_source(quiet_request("glx-stereo:wait=20,socket=" + socket()));
  for (int i = 0; i < 5; ++i) {
    const std::optional<StereoVideoFrame> f = source->next();
    ASSERT_TRUE(f);
    EXPECT_FALSE(f->disparity);
  }
}

TEST_F(GlxStereoSourceTest, DlsymRtldNextStillMeansAfterTheCaller) {
  // The interposer answers dlsym for GL's functions; anything else a game's code looks up, RTLD_NEXT
  // included, resolves as without it (other overlays and wrappers in the game depend on that).
  const auto plain = test::run_command(NELF_RTLD_NEXT_PROBE);
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_NE(plain.out.find("libc.so"), std::string::npos) << plain.out;
  const auto preloaded =
      test::run_command("LD_PRELOAD=" + test::shell_quote(glx_stereo_library_path()) + " " + NELF_RTLD_NEXT_PROBE);
  ASSERT_EQ(preloaded.status, 0) << preloaded.err;
  EXPECT_EQ(preloaded.out, glx_stereo_library_path() + "\n");
}

TEST_F(GlxStereoSourceTest, AGameThatDrawsOnePictureGivesItsViewsAtEachSwap) {
  // Both eyes side by side, top and bottom, frame-packed: the layout found as for a file, through
  // GLFW and SDL2; the views are the game's, upright, the newest frame each time.
  struct Case {
    const char* toolkit;
    const char* mode;
    std::optional<StereoLayout> layout;
    int view_w, view_h;
    const char* said;
  };
  for (const Case& c : {Case{"glfw", "sbs", std::nullopt, 320, 180, "layout sbs (aspect)"},
                        Case{"sdl2", "tab", std::nullopt, 320, 180, "layout tab (aspect)"},
                        Case{"glfw", "fp", std::nullopt, 1280, 720, "layout fp (frame-size)"},
                        Case{"sdl2", "sbs-half", StereoLayout::sbs_half, 160, 180, "layout sbs-half (flag)"}}) {
    SCOPED_TRACE(c.mode);
    const std::string size = std::string(c.mode) == "fp" ? "1280x720" : "320x180";
    test::TestGame game({"--toolkit", c.toolkit, "--mode", c.mode, "--size", size, "--fps", "30"}, interposed());
    auto source = open_source(quiet_request("glx-stereo:wait=20,socket=" + socket(), c.layout));
    const SourceInfo info = source->info();
    EXPECT_TRUE(info.live);
    EXPECT_EQ(info.view.width, c.view_w);
    EXPECT_EQ(info.view.height, c.view_h);
    EXPECT_NE(info.description.find("the window of an OpenGL game (process "), std::string::npos) << info.description;
    EXPECT_NE(info.description.find(c.said), std::string::npos) << info.description;
    std::optional<std::uint32_t> last;
    for (int i = 0; i < 6; ++i) {
      const std::optional<StereoVideoFrame> f = source->next();
      ASSERT_TRUE(f);
      ASSERT_EQ(f->width, c.view_w);
      ASSERT_EQ(f->height, c.view_h);
      EXPECT_GT(f->captured_ns, 0);
      EXPECT_NE(f->left, f->right);  // the bars at opposite disparities
      test::expect_game_background_below_the_bars(f->left, f->width, f->height);
      test::expect_game_background_below_the_bars(f->right, f->width, f->height);
      const auto left = read_frame_stamp(f->left.data(), f->width, f->height, f->bits);
      const auto right = read_frame_stamp(f->right.data(), f->width, f->height, f->bits);
      ASSERT_TRUE(left && right) << "frame " << i;  // a flipped or misplaced view reads as no stamp
      EXPECT_EQ(*left, *right);
      if (last) {
        EXPECT_GT(left->frame, *last);
      }
      last = left->frame;
    }
  }
}

TEST_F(GlxStereoSourceTest, AGameThatNeverSwapsIsSaid) {
  try {
    open_source(quiet_request("glx-stereo:wait=0.5,socket=" + socket()));
    FAIL() << "no game, yet a source";
  } catch (const GameDidNotSwap& e) {
    EXPECT_NE(std::string(e.what()).find("no OpenGL game swapped a frame in 0.5 s"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(socket()));  // nelf's socket is gone with the source
  try {
    open_source(quiet_request("glx-stereo:wait=1"));
    FAIL() << "no socket, yet a source";
  } catch (const UserError& e) {
    EXPECT_EQ(e.status(), 2);
    EXPECT_NE(std::string(e.what()).find("socket=PATH is missing"), std::string::npos) << e.what();
  }
  try {
    open_source(quiet_request("glx-stereo:socket=" + socket(), StereoLayout::alt));
    FAIL() << "a layout of two frames, yet a source";
  } catch (const UserError& e) {
    EXPECT_EQ(e.status(), 2);
    EXPECT_NE(std::string(e.what()).find("layout alt needs a file"), std::string::npos) << e.what();
  }
}

TEST_F(GlxStereoSourceTest, WhatTheGameDrawsIntoBothBackBuffersIsInBothEyes) {
  // A HUD drawn with glDrawBuffer(GL_BACK) after the eyes, as games draw one (hud.hpp): with
  // glDrawArrays, in immediate mode, through a display list that also moves the matrix, with
  // glBitmap, which moves the raster position, and glCopyPixels. Each lands once in each eye, where
  // the game put it.
  using namespace test_game;
  constexpr int kW = 320, kH = 180;
  const auto white = [](const StereoVideoFrame& f, bool left, double x, double row) {
    const std::uint8_t* p =
        &(left ? f.left : f.right)[(static_cast<std::size_t>(row) * f.width + static_cast<std::size_t>(x)) * 4];
    return p[0] > 230 && p[1] > 230 && p[2] > 230;
  };
  const double bar_x = (kHudX0 + kHudX1) / 2 * kW, bar_row = (kHudTop + kHudBottom) / 2 * kH;
  for (const char* hud : {"arrays", "immediate", "list", "bitmap", "copy"}) {
    SCOPED_TRACE(hud);
    test::TestGame game({"--mode", "quad-buffer", "--size", "320x180", "--fps", "30", "--hud", hud}, interposed());
    auto source = open_source(quiet_request("glx-stereo:wait=20,socket=" + socket()));
    const std::optional<StereoVideoFrame> f = source->next();
    ASSERT_TRUE(f);
    ASSERT_EQ(f->width, kW);
    ASSERT_EQ(f->bits, 8);
    for (const bool left : {true, false}) {
      SCOPED_TRACE(left ? "left eye" : "right eye");
      if (std::string(hud) == "bitmap") {
        const double row = kHudBlockBottom * kH - kHudBlock / 2.0;
        for (int i = 0; i < kHudBlocks + 3; ++i) {
          const double x = kHudX0 * kW + i * kHudBlockStep;
          EXPECT_EQ(white(*f, left, x + kHudBlock / 2.0, row), i < kHudBlocks) << "block " << i;
          EXPECT_FALSE(white(*f, left, x + kHudBlock * 1.5, row)) << "after block " << i;
        }
        continue;
      }
      EXPECT_TRUE(white(*f, left, bar_x, bar_row));
      if (std::string(hud) == "list" || std::string(hud) == "copy") {
        EXPECT_TRUE(white(*f, left, bar_x + kHudListShift * kW, bar_row));
        EXPECT_FALSE(white(*f, left, bar_x + 2 * kHudListShift * kW, bar_row));
      }
    }
  }
}

}  // namespace
}  // namespace nelf
