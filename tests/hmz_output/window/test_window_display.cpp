// The GLFW window outputs on a private Xvfb server: what present() puts on screen (read from the
// X server), and the errors a user meets when there is no display or no stereo.
#include <gtest/gtest.h>

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <thread>
#include <vector>

#include "compositor/gl/gl_compositor.hpp"
#include "hmz_output/display_drivers.hpp"
#include "hmz_output/packing.hpp"
#include "hmz_output/window_display.hpp"
#include "optics/profile.hpp"
#include "support/x11_window.hpp"
#include "support/xvfb.hpp"

namespace nelf {
namespace {
// This file's own names: its suite is compiled as one unit (tests/CMakeLists.txt).
namespace test_window_display {

using Rgb = std::array<int, 3>;

DisplayOptions frame_packed_options() {
  DisplayOptions options;
  options.signal = *find_signal("hdmi-fp-720p60");
  options.packed = {options.signal.packed_width(1280), options.signal.packed_height(720)};
  return options;
}

// Fills the packed frame's quadrants: top-left red, top-right green, bottom-left blue, bottom-right
// white (rows counted from the packed frame's top, the compositor's memory convention).
void draw_quadrants(const Display& display) {
  const auto [w, h] = display.packed_size();
  const GLuint fbo = display.packed_framebuffer();
  glEnable(GL_SCISSOR_TEST);
  const std::array<std::array<GLfloat, 4>, 4> colours{{{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 1}, {1, 1, 1, 1}}};
  for (int q = 0; q < 4; ++q) {
    const int x0 = (q % 2) * (w / 2), y0 = (q / 2) * (h / 2);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
    glScissor(x0, y0, w / 2, h / 2);
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, colours[q].data());
  }
  glDisable(GL_SCISSOR_TEST);
}

test::WindowCapture read_window() { return test::capture_window(glfwGetCurrentContext()); }

constexpr Rgb red{255, 0, 0}, green{0, 255, 0}, blue{0, 0, 255}, white{255, 255, 255}, black{0, 0, 0};

class WindowDisplayTest : public ::testing::Test {
 protected:
  test::XvfbServer xvfb_;
  test::ScopedDisplay display_env_{xvfb_.display_name()};
};

TEST_F(WindowDisplayTest, ShowsThePackedFrameOneToOneWhenItFitsTopRowAtTheTop) {
  auto display = open_window_display(frame_packed_options(), WindowMode::window);
  ASSERT_NE(display->packed_framebuffer(), 0u);
  EXPECT_EQ(display->packed_size(), (std::array<int, 2>{1280, 1470}));
  draw_quadrants(*display);
  display->present();
  const test::WindowCapture screen = read_window();
  // The 1920x1600 screen has room for the frame 1:1.
  ASSERT_EQ(screen.width, 1280);
  ASSERT_EQ(screen.height, 1470);
  EXPECT_EQ(screen.at(0, 0), red);
  EXPECT_EQ(screen.at(639, 734), red);
  EXPECT_EQ(screen.at(640, 0), green);
  EXPECT_EQ(screen.at(1279, 734), green);
  EXPECT_EQ(screen.at(0, 735), blue);
  EXPECT_EQ(screen.at(639, 1469), blue);
  EXPECT_EQ(screen.at(640, 735), white);
  EXPECT_EQ(screen.at(1279, 1469), white);
}

// What the player's CPU path does: a packed frame made in BGRA bytes (ChannelOrder::bgra, row 0 the
// top row) uploaded into packed_texture() as GL_BGRA. Its colours reach the window as they are (on
// llvmpipe upload and 1:1 blit are then plain copies; a wrong order would swap red and blue).
TEST_F(WindowDisplayTest, ABgraPackedFrameUploadedIntoThePackedTextureShowsItsColours) {
  auto display = open_window_display(frame_packed_options(), WindowMode::window);
  const auto [w, h] = display->packed_size();
  const std::array<Rgb, 4> colours{{{200, 40, 30}, {20, 160, 90}, {10, 60, 230}, {250, 250, 5}}};
  std::vector<std::uint8_t> bgra(static_cast<std::size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Rgb& c = colours[(y < h / 2 ? 0 : 2) + (x < w / 2 ? 0 : 1)];
      std::uint8_t* p = &bgra[(static_cast<std::size_t>(y) * w + x) * 4];
      p[0] = static_cast<std::uint8_t>(c[2]);
      p[1] = static_cast<std::uint8_t>(c[1]);
      p[2] = static_cast<std::uint8_t>(c[0]);
      p[3] = 255;
    }
  glTextureSubImage2D(display->packed_texture(), 0, 0, 0, w, h, GL_BGRA, GL_UNSIGNED_BYTE, bgra.data());
  ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  display->present();
  const test::WindowCapture screen = read_window();
  ASSERT_EQ(screen.width, w);
  ASSERT_EQ(screen.height, h);
  EXPECT_EQ(screen.at(0, 0), colours[0]);
  EXPECT_EQ(screen.at(w - 1, 0), colours[1]);
  EXPECT_EQ(screen.at(0, h - 1), colours[2]);
  EXPECT_EQ(screen.at(w - 1, h - 1), colours[3]);
  EXPECT_EQ(screen.at(w / 2 - 1, h / 2 - 1), colours[0]);
  EXPECT_EQ(screen.at(w / 2, h / 2), colours[3]);
}

// The preview caption: flat over the picture at the bottom centre, 1/16 of the window's height (a
// 20-row caption there on the 1470-row window: scaled ×4.6), its top row at the top; gone again when
// cleared.
TEST_F(WindowDisplayTest, APreviewCaptionShowsFlatAtTheBottomCentreUntilCleared) {
  auto display = open_window_display(frame_packed_options(), WindowMode::window);
  EXPECT_TRUE(display->takes_preview_caption());
  glClearNamedFramebufferfv(display->packed_framebuffer(), GL_COLOR, 0, std::array<GLfloat, 4>{0, 0, 0, 1}.data());
  PreviewCaption caption{100, 20, std::vector<std::uint8_t>(100u * 20u * 4u, 255)};
  for (int x = 0; x < 100; ++x) caption.rgba[static_cast<std::size_t>(x) * 4 + 1] = 0;  // top row magenta
  display->set_preview_caption(caption);
  display->present();
  test::WindowCapture screen = read_window();
  ASSERT_EQ(screen.height, 1470);
  const int h = static_cast<int>(std::lround(1470 / 16.0)), w = static_cast<int>(std::lround(100 * 1470 / 16.0 / 20));
  const int bottom = 1470 - 1470 / 12, top = bottom - h, left = (1280 - w) / 2;
  EXPECT_EQ(screen.at(640, bottom - h / 2), white);
  EXPECT_EQ(screen.at(left + 3, bottom - 3), white);
  EXPECT_EQ(screen.at(left + w - 4, top + h / 2), white);
  EXPECT_EQ(screen.at(640, top + 1), (Rgb{255, 0, 255}));  // row 0 on top
  EXPECT_EQ(screen.at(left - 3, bottom - h / 2), black);
  EXPECT_EQ(screen.at(640, bottom + 3), black);
  EXPECT_EQ(screen.at(640, top - 3), black);
  display->set_preview_caption({});
  display->present();
  screen = read_window();
  EXPECT_EQ(screen.at(640, bottom - h / 2), black);
}

TEST_F(WindowDisplayTest, ScalesToFitAResizedWindowWithBlackBars) {
  auto display = open_window_display(frame_packed_options(), WindowMode::window);
  GLFWwindow* window = glfwGetCurrentContext();
  glfwSetWindowSize(window, 1000, 500);
  // Xvfb has no window manager: the resize is immediate once the server has seen it.
  int width = 0, height = 0;
  for (int i = 0; i < 200 && (width != 1000 || height != 500); ++i) {
    display->poll_events();
    glfwGetFramebufferSize(window, &width, &height);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(width, 1000);
  ASSERT_EQ(height, 500);
  draw_quadrants(*display);
  // Mesa notices the new drawable size on the next swap: the first frame after a resize can be lost
  // (harmless while playing, frames keep coming).
  display->present();
  display->present();
  const test::WindowCapture screen = read_window();
  // Scale 500/1470: the frame is 435x500, centred, with 282-column bars either side.
  const int frame_w = 435, x0 = (1000 - frame_w) / 2;
  EXPECT_EQ(screen.at(10, 250), black);
  EXPECT_EQ(screen.at(x0 - 2, 250), black);
  EXPECT_EQ(screen.at(x0 + frame_w + 1, 250), black);
  EXPECT_EQ(screen.at(990, 250), black);
  EXPECT_EQ(screen.at(x0 + frame_w / 4, 125), red);
  EXPECT_EQ(screen.at(x0 + 3 * frame_w / 4, 125), green);
  EXPECT_EQ(screen.at(x0 + frame_w / 4, 375), blue);
  EXPECT_EQ(screen.at(x0 + 3 * frame_w / 4, 375), white);
  EXPECT_EQ(screen.at(x0 + 2, 2), red);
  EXPECT_EQ(screen.at(x0 + frame_w - 3, 497), white);
}

TEST_F(WindowDisplayTest, WindowIsSizedToTheWorkAreaKeepingTheAspect) {
  // A packed frame taller than the 1600-row screen is shrunk to fit, aspect kept.
  DisplayOptions options = frame_packed_options();
  options.signal = *find_signal("hdmi-fp-1080p24");
  options.packed = {1920, 2205};
  auto display = open_window_display(options, WindowMode::window);
  int width = 0, height = 0;
  glfwGetFramebufferSize(glfwGetCurrentContext(), &width, &height);
  EXPECT_EQ(height, 1600);
  EXPECT_EQ(width, 1393);  // floor(1920 * 1600 / 2205)
}

TEST_F(WindowDisplayTest, SoftwareSwapsAreNotVsyncAndTheRefreshIsKnown) {
  auto display = open_window_display(frame_packed_options(), WindowMode::window);
  EXPECT_TRUE(display->context()->is_software()) << display->context()->renderer();
  EXPECT_FALSE(display->vsync());
  EXPECT_GT(display->refresh_hz(), 0.0);
  EXPECT_FALSE(display->close_requested());
  EXPECT_TRUE(display->poll_events().empty());
  const std::string description = display->description();
  EXPECT_NE(description.find("window 1280x1470 on " + xvfb_.display_name()), std::string::npos) << description;
  EXPECT_NE(description.find("no vsync"), std::string::npos) << description;
}

TEST_F(WindowDisplayTest, ClosingTheWindowIsReported) {
  auto display = open_window_display(frame_packed_options(), WindowMode::window);
  glfwSetWindowShouldClose(glfwGetCurrentContext(), GLFW_TRUE);
  EXPECT_TRUE(display->close_requested());
}

TEST_F(WindowDisplayTest, TwoDisplaysInTurnEachGetAWorkingContext) {
  for (int i = 0; i < 2; ++i) {
    auto display = open_window_display(frame_packed_options(), WindowMode::window);
    draw_quadrants(*display);
    display->present();
    EXPECT_EQ(read_window().at(0, 0), red);
  }
}

TEST_F(WindowDisplayTest, QuadBufferOnMesaSaysThereAreNoStereoVisuals) {
  try {
    display_driver("quad-buffer").open_display(frame_packed_options());
    FAIL() << "Mesa offered a stereo visual";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("no stereo visuals"), std::string::npos) << message;
    EXPECT_NE(message.find("Stereo"), std::string::npos) << message;
    EXPECT_NE(message.find("--output fullscreen"), std::string::npos) << message;
    EXPECT_NE(message.find("--output kms"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // A failed open leaves GLFW usable.
  auto display = open_window_display(frame_packed_options(), WindowMode::window);
  EXPECT_NE(display->packed_framebuffer(), 0u);
}

// Xvfb's one RandR output is called "screen", its mode is the server's screen size, refresh unknown.
TEST_F(WindowDisplayTest, FullscreenWithoutAnHmzListsTheMonitors) {
  try {
    open_window_display(frame_packed_options(), WindowMode::fullscreen);
    FAIL() << "went fullscreen without an HMZ monitor";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(),
                 "fullscreen: no monitor name contains \"HMZ\"; connected monitors: screen 1920x1600; pass --monitor "
                 "NAME");
  }
}

TEST_F(WindowDisplayTest, FullscreenOnAMonitorInAnotherModeGivesTheXrandrCommands) {
  DisplayOptions options = frame_packed_options();
  options.monitor = "screen";
  try {
    open_window_display(options, WindowMode::fullscreen);
    FAIL() << "went fullscreen on a 1920x1600 monitor";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(),
                 "fullscreen: monitor screen is in mode 1920x1600, but the hdmi-fp-720p60 signal needs 1280x1470 "
                 "pixels 1:1; add and select the mode with:\n"
                 "  xrandr --newmode \"1280x1470_60_fp\" 148.50 1280 1390 1430 1650 1470 1475 1480 1500 +hsync +vsync\n"
                 "  xrandr --addmode screen 1280x1470_60_fp\n"
                 "  xrandr --output screen --mode 1280x1470_60_fp");
  }
}

// Thin lines, one pixel wide, at packed column 100 and packed row 200: they survive only 1:1.
void draw_hairlines(const Display& display) {
  const GLuint fbo = display.packed_framebuffer();
  const GLfloat black_colour[4] = {0, 0, 0, 1}, white_colour[4] = {1, 1, 1, 1};
  glClearNamedFramebufferfv(fbo, GL_COLOR, 0, black_colour);
  glEnable(GL_SCISSOR_TEST);
  glScissor(100, 0, 1, display.packed_size()[1]);
  glClearNamedFramebufferfv(fbo, GL_COLOR, 0, white_colour);
  glScissor(0, 200, display.packed_size()[0], 1);
  glClearNamedFramebufferfv(fbo, GL_COLOR, 0, white_colour);
  glDisable(GL_SCISSOR_TEST);
}

class PackedSizeScreenTest : public ::testing::Test {
 protected:
  test::XvfbServer xvfb_{1280, 1470};
  test::ScopedDisplay display_env_{xvfb_.display_name()};
};

TEST_F(PackedSizeScreenTest, FullscreenShowsThePackedFramePixelForPixel) {
  DisplayOptions options = frame_packed_options();
  options.monitor = "SCREEN";
  auto display = open_window_display(options, WindowMode::fullscreen);
  EXPECT_NE(display->description().find("fullscreen on screen 1280x1470"), std::string::npos) << display->description();
  EXPECT_DOUBLE_EQ(display->refresh_hz(), 60.0);  // Xvfb reports no refresh: the signal's
  draw_hairlines(*display);
  display->present();
  const test::WindowCapture screen = read_window();
  ASSERT_EQ(screen.width, 1280);
  ASSERT_EQ(screen.height, 1470);
  EXPECT_EQ(screen.at(100, 50), white);
  EXPECT_EQ(screen.at(99, 50), black);
  EXPECT_EQ(screen.at(101, 50), black);
  EXPECT_EQ(screen.at(700, 200), white);
  EXPECT_EQ(screen.at(700, 199), black);
  EXPECT_EQ(screen.at(700, 201), black);
}

TEST_F(PackedSizeScreenTest, ToggleFullscreenAndBack) {
  DisplayOptions options = frame_packed_options();
  options.monitor = "screen";
  auto display = open_window_display(options, WindowMode::window);
  EXPECT_EQ(display->toggle_fullscreen(), "fullscreen on screen");
  EXPECT_NE(display->description().find("fullscreen on screen"), std::string::npos) << display->description();
  draw_hairlines(*display);
  display->present();
  display->present();
  EXPECT_EQ(read_window().at(100, 50), white);
  EXPECT_EQ(display->toggle_fullscreen(), "window");
  EXPECT_EQ(display->description().rfind("window 1280x1470", 0), 0u) << display->description();
}

TEST_F(WindowDisplayTest, ToggleFullscreenWithoutAnHmzSaysWhyInOneLine) {
  auto display = open_window_display(frame_packed_options(), WindowMode::window);
  EXPECT_EQ(display->toggle_fullscreen(),
            "fullscreen: no monitor name contains \"HMZ\"; connected monitors: screen 1920x1600; pass --monitor NAME");
  EXPECT_EQ(display->description().rfind("window 1280x1470", 0), 0u) << display->description();
}

std::vector<KeyPress> poll_until(Display& display, std::size_t count) {
  std::vector<KeyPress> keys;
  for (int i = 0; i < 200 && keys.size() < count; ++i) {
    for (const auto& key : display.poll_events()) keys.push_back(key);
    if (keys.size() < count) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return keys;
}

TEST_F(WindowDisplayTest, KeysArriveAsTypedCharactersOrByName) {
  auto display = open_window_display(frame_packed_options(), WindowMode::window);
  GLFWwindow* window = glfwGetCurrentContext();
  // US layout on Xvfb: '+' is Shift+'=' there, but the key press carries the character typed.
  for (const char* key : {"plus", "minus", "bracketleft", "bracketright", "s", "space", "Left", "Right", "Up", "Down",
                          "Escape", "Return", "Page_Up"})
    test::send_key(window, key, std::string(key) == "plus");
  test::send_key(window, "q", false, true);
  const auto keys = poll_until(*display, 14);
  ASSERT_EQ(keys.size(), 14u);
  using N = KeyPress::Named;
  EXPECT_TRUE(keys[0].is(U'+'));
  EXPECT_TRUE(keys[1].is(U'-'));
  EXPECT_TRUE(keys[2].is(U'['));
  EXPECT_TRUE(keys[3].is(U']'));
  EXPECT_TRUE(keys[4].is(U's'));
  EXPECT_FALSE(keys[4].shift);
  EXPECT_TRUE(keys[5].is(N::space));
  EXPECT_TRUE(keys[6].is(N::left));
  EXPECT_TRUE(keys[7].is(N::right));
  EXPECT_TRUE(keys[8].is(N::up));
  EXPECT_TRUE(keys[9].is(N::down));
  EXPECT_TRUE(keys[10].is(N::escape));
  EXPECT_TRUE(keys[11].is(N::enter));
  EXPECT_TRUE(keys[12].is(N::page_up));
  EXPECT_TRUE(keys[13].is(U'q'));
  EXPECT_TRUE(keys[13].ctrl);
  EXPECT_TRUE(display->poll_events().empty());
}

Image flat(int width, int height, Rgba colour) {
  Image image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) image.at(x, y) = colour;
  return image;
}

// Mean RGB (0-255) of a rectangle given from the window's top.
std::array<double, 3> mean(const test::WindowCapture& screen, int x0, int y0, int w, int h) {
  std::array<double, 3> sum{};
  for (int y = y0; y < y0 + h; ++y)
    for (int x = x0; x < x0 + w; ++x)
      for (int k = 0; k < 3; ++k) sum[k] += screen.at(x, y)[k];
  for (auto& v : sum) v /= static_cast<double>(w) * h;
  return sum;
}

// The path `nelf play` takes: the GL compositor renders both eyes in the window's own (GLX) context
// straight into the packed framebuffer at the eye areas, then present().
TEST_F(WindowDisplayTest, TheCompositorRendersIntoThePackedFrameInTheWindowsContext) {
  const DisplayOptions options = frame_packed_options();
  auto display = open_window_display(options, WindowMode::window);
  GlCompositor compositor(load_profile("hmz-t1"), {1, std::nullopt}, display->context());
  const gl::Texture left = upload_texture(flat(320, 180, {0.f, 1.f, 0.f, 1.f}), GL_RGBA8);
  const gl::Texture right = upload_texture(flat(320, 180, {1.f, 0.f, 0.f, 1.f}), GL_RGBA8);
  for (const Eye eye : {Eye::left, Eye::right}) {
    const auto area = eye_area(options.signal, eye, 1280, 720);
    ASSERT_TRUE(area);
    compositor.render_eye(eye, {(eye == Eye::left ? left : right).id(), 320, 180, 0.0},
                          {display->packed_framebuffer(), area->x, area->y});
  }
  display->present();
  const test::WindowCapture screen = read_window();
  ASSERT_EQ(screen.height, 1470);
  const auto top = mean(screen, 0, 0, 1280, 720), gap = mean(screen, 0, 720, 1280, 30),
             bottom = mean(screen, 0, 750, 1280, 720);
  EXPECT_GT(top[1], 100.0);  // the left eye's elemental images: green
  EXPECT_LT(top[0], 5.0);
  EXPECT_GT(bottom[0], 100.0);  // the right eye's: red
  EXPECT_LT(bottom[1], 5.0);
  EXPECT_EQ(gap, (std::array<double, 3>{0, 0, 0}));  // the gap rows stay black
}

TEST_F(WindowDisplayTest, NoOpenGL45IsAClearError) {
  // Mesa's override makes the driver offer OpenGL 3.3 only.
  setenv("MESA_GL_VERSION_OVERRIDE", "3.3", 1);
  try {
    open_window_display(frame_packed_options(), WindowMode::window);
    unsetenv("MESA_GL_VERSION_OVERRIDE");
    FAIL() << "opened a 4.5 context on a 3.3 driver";
  } catch (const std::runtime_error& e) {
    unsetenv("MESA_GL_VERSION_OVERRIDE");
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("OpenGL 4.5 core is not available on this X display (", 0), 0u) << message;
    EXPECT_NE(message.find("--output kms"), std::string::npos) << message;
  }
  auto display = open_window_display(frame_packed_options(), WindowMode::window);  // the override is gone
  EXPECT_NE(display->packed_framebuffer(), 0u);
}

TEST_F(WindowDisplayTest, LosingTheXServerIsAnExceptionNotAnExit) {
  auto display = open_window_display(frame_packed_options(), WindowMode::window);
  display->present();
  xvfb_.kill_now();
  EXPECT_THROW(
      {
        for (int i = 0; i < 10; ++i) {  // the loss shows on the first request that reaches the socket
          display->poll_events();
          display->present();
        }
      },
      std::runtime_error);
  EXPECT_TRUE(display->close_requested());
  display.reset();  // closing after the loss must not crash either

  // And a later display on another server works.
  test::XvfbServer another;
  test::ScopedDisplay use_it(another.display_name());
  auto next = open_window_display(frame_packed_options(), WindowMode::window);
  draw_quadrants(*next);
  next->present();
  EXPECT_EQ(read_window().at(0, 0), red);
}

TEST(WindowDisplayErrors, NoDisplayVariable) {
  test::ScopedDisplay no_display("");
  try {
    open_window_display(frame_packed_options(), WindowMode::window);
    FAIL() << "opened a window without DISPLAY";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(),
                 "no display: DISPLAY is not set; run inside a desktop session, under xvfb-run, or use --output kms");
  }
}

TEST(WindowDisplayErrors, NoXServerAtDisplay) {
  test::ScopedDisplay nowhere(":9873");
  try {
    open_window_display(frame_packed_options(), WindowMode::window);
    FAIL() << "opened a window on a display without a server";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("no display: cannot connect to the X server at DISPLAY=:9873", 0), 0u) << message;
    EXPECT_NE(message.find("--output kms"), std::string::npos) << message;
  }
}

TEST(WindowDisplayErrors, QuadBufferNeedsBothEyes) {
  DisplayOptions options = frame_packed_options();
  options.signal = *find_signal("left");
  options.packed = {1280, 720};
  EXPECT_THROW(display_driver("quad-buffer").open_display(options), std::invalid_argument);
}

}  // namespace test_window_display
}  // namespace
}  // namespace nelf
