// nelf-test-game: a small OpenGL game for the live-capture tests and the latency benchmark. It
// draws both eyes into its window the way stereo games do (side-by-side full or half, top-bottom
// full or half, a 1280×1470 frame-packed window), through GLFW or SDL2, at a fixed frame rate, and
// stamps every frame into both eyes with its counter and the CLOCK_MONOTONIC time it was presented
// (core/frame_stamp.hpp), so that a capture says which frame it caught and how late.
//
//   nelf-test-game [--toolkit glfw|sdl2] [--mode sbs|sbs-half|tab|tab-half|fp|quad-buffer]
//                  [--fps N] [--size WxH] [--frames N] [--duration S] [--title T] [--log FILE]
//                  [--reopen-after N] [--exit-status N] [--scene bars|planes]
//                  [--hud arrays|immediate|list|bitmap|copy] [--swap-interval N]
//
// --size is one eye's size (default 1280x720); the window is sized from it and the mode (fp: the
// frame-packed window of that eye size, 1280x720 → 1280x1470). The game follows its window's size
// when it is resized. It ends after --frames or --duration, when its window is closed, or on
// SIGINT/SIGTERM, with status 0; bad options end it with status 2. --log writes "frame,present_ns"
// for every frame presented. --reopen-after N closes the window after N frames and opens a new
// one, as games do for a splash screen or a new video mode; --exit-status N is the status it ends
// with (after --frames or --duration), for the tests of `nelf run`. --scene planes draws, instead of
// the flat bars, two textured planes in perspective with a depth buffer, as a 3D game does
// (planes_scene.hpp), for the tests of the game's depth. --hud (quad-buffer only) draws a HUD over
// both eyes at once with glDrawBuffer(GL_BACK), with glDrawArrays, glBegin/glEnd, a display list,
// glBitmap or glCopyPixels (hud.hpp). --swap-interval N (default 0) asks the toolkit for vsync
// every N refreshes and lets the buffer swaps pace the game instead of sleeping to --fps (which
// still sets the animation's speed): under `nelf run`, nelf's display refreshes pace it.
// epoxy before the toolkits' headers, which would include GL/gl.h.
#include <epoxy/gl.h>

#include <GLFW/glfw3.h>
#include <SDL2/SDL.h>
#include <time.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/frame_stamp.hpp"
#include "game/hud.hpp"
#include "game/planes_scene.hpp"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

enum class Toolkit { glfw, sdl2 };
enum class Mode { sbs, sbs_half, tab, tab_half, fp, quad_buffer };
enum class Hud { none, arrays, immediate, list, bitmap, copy };

struct Options {
  Toolkit toolkit = Toolkit::glfw;
  Mode mode = Mode::sbs;
  std::string mode_name = "sbs";
  double fps = 60;
  int eye_width = 1280, eye_height = 720;
  long frames = 0;        // 0: no limit
  double duration_s = 0;  // 0: no limit
  std::string title;
  std::string log;
  long reopen_after = 0;  // 0: never
  int exit_status = 0;
  bool planes = false;  // --scene planes
  Hud hud = Hud::none;
  int swap_interval = 0;  // 0: the game sleeps to --fps; N: the swaps pace it
};

class BadUsage : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

double number(const std::string& option, const char* text) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text, &end);
  if (errno || end == text || *end || !std::isfinite(v)) throw BadUsage(option + " needs a number, got '" + text + "'");
  return v;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> const char* {
      if (i + 1 >= argc) throw BadUsage(a + " needs a value");
      return argv[++i];
    };
    if (a == "--toolkit") {
      const std::string v = value();
      if (v == "glfw")
        o.toolkit = Toolkit::glfw;
      else if (v == "sdl2")
        o.toolkit = Toolkit::sdl2;
      else
        throw BadUsage("--toolkit must be glfw or sdl2, got '" + v + "'");
    } else if (a == "--mode") {
      o.mode_name = value();
      if (o.mode_name == "sbs")
        o.mode = Mode::sbs;
      else if (o.mode_name == "sbs-half")
        o.mode = Mode::sbs_half;
      else if (o.mode_name == "tab")
        o.mode = Mode::tab;
      else if (o.mode_name == "tab-half")
        o.mode = Mode::tab_half;
      else if (o.mode_name == "fp")
        o.mode = Mode::fp;
      else if (o.mode_name == "quad-buffer")
        o.mode = Mode::quad_buffer;
      else
        throw BadUsage("--mode must be sbs, sbs-half, tab, tab-half, fp or quad-buffer, got '" + o.mode_name + "'");
    } else if (a == "--fps") {
      o.fps = number(a, value());
      if (!(o.fps >= 1 && o.fps <= 1000)) throw BadUsage("--fps must be in 1..1000");
    } else if (a == "--size") {
      const std::string v = value();
      int w = 0, h = 0;
      char tail = 0;
      if (std::sscanf(v.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 128 || h < 128 || w > 8192 || h > 8192 || w % 2)
        throw BadUsage("--size must be WxH, an even width, 128..8192 per side, got '" + v + "'");
      o.eye_width = w;
      o.eye_height = h;
    } else if (a == "--frames") {
      const double v = number(a, value());
      if (v < 1 || v != std::floor(v)) throw BadUsage("--frames must be a whole number ≥ 1");
      o.frames = static_cast<long>(v);
    } else if (a == "--duration") {
      o.duration_s = number(a, value());
      if (!(o.duration_s > 0)) throw BadUsage("--duration must be > 0 seconds");
    } else if (a == "--scene") {
      const std::string v = value();
      if (v != "bars" && v != "planes") throw BadUsage("--scene must be bars or planes, got '" + v + "'");
      o.planes = v == "planes";
    } else if (a == "--hud") {
      const std::string v = value();
      if (v == "arrays")
        o.hud = Hud::arrays;
      else if (v == "immediate")
        o.hud = Hud::immediate;
      else if (v == "list")
        o.hud = Hud::list;
      else if (v == "bitmap")
        o.hud = Hud::bitmap;
      else if (v == "copy")
        o.hud = Hud::copy;
      else
        throw BadUsage("--hud must be arrays, immediate, list, bitmap or copy, got '" + v + "'");
    } else if (a == "--title") {
      o.title = value();
    } else if (a == "--log") {
      o.log = value();
    } else if (a == "--reopen-after") {
      const double v = number(a, value());
      if (v < 1 || v != std::floor(v)) throw BadUsage("--reopen-after must be a whole number ≥ 1");
      o.reopen_after = static_cast<long>(v);
    } else if (a == "--swap-interval") {
      const double v = number(a, value());
      if (v < 0 || v > 8 || v != std::floor(v)) throw BadUsage("--swap-interval must be 0..8");
      o.swap_interval = static_cast<int>(v);
    } else if (a == "--exit-status") {
      const double v = number(a, value());
      if (v < 0 || v > 125 || v != std::floor(v)) throw BadUsage("--exit-status must be 0..125");
      o.exit_status = static_cast<int>(v);
    } else if (a == "--help" || a == "-h") {
      std::puts(
          "nelf-test-game [--toolkit glfw|sdl2] [--mode sbs|sbs-half|tab|tab-half|fp|quad-buffer] [--fps N]\n"
          "               [--size WxH] [--frames N] [--duration S] [--title T] [--log FILE]\n"
          "               [--reopen-after N] [--exit-status N] [--scene bars|planes]\n"
          "               [--hud arrays|immediate|list|bitmap|copy] [--swap-interval N]");
      std::exit(0);
    } else {
      throw BadUsage("unknown option '" + a + "' (--help lists them)");
    }
  }
  if (o.title.empty()) o.title = "nelf test game " + o.mode_name;
  if (o.hud != Hud::none && o.mode != Mode::quad_buffer) throw BadUsage("--hud needs --mode quad-buffer");
  return o;
}

// The window's size for one eye's size and the mode.
void window_size(const Options& o, int& w, int& h) {
  switch (o.mode) {
    case Mode::sbs:
      w = 2 * o.eye_width, h = o.eye_height;
      return;
    case Mode::sbs_half:
      w = o.eye_width, h = o.eye_height;
      return;
    case Mode::tab:
      w = o.eye_width, h = 2 * o.eye_height;
      return;
    case Mode::tab_half:
      w = o.eye_width, h = o.eye_height;
      return;
    // HDMI 1.4a frame packing: the left eye on top, a gap of 1/24 of an eye's height (30 rows at
    // 720, 45 at 1080), the right eye below.
    case Mode::fp:
      w = o.eye_width, h = 2 * o.eye_height + o.eye_height / 24;
      return;
    case Mode::quad_buffer:
      w = o.eye_width, h = o.eye_height;
      return;
  }
}

struct Rect {
  int x, y, w, h;  // rows from the top
};

// Where each eye goes in a window of w × h (following resizes proportionally).
void eye_rects(Mode mode, int w, int h, Rect& left, Rect& right) {
  switch (mode) {
    case Mode::sbs:
    case Mode::sbs_half:
      left = {0, 0, w / 2, h}, right = {w / 2, 0, w / 2, h};
      return;
    case Mode::tab:
    case Mode::tab_half:
      left = {0, 0, w, h / 2}, right = {0, h / 2, w, h / 2};
      return;
    case Mode::fp: {
      const int eye = h * 24 / 49;  // 2 eyes + 1/24 of one: 49/24 eye heights
      left = {0, 0, w, eye}, right = {0, h - eye, w, eye};
      return;
    }
    case Mode::quad_buffer:
      left = right = {0, 0, w, h};
      return;
  }
}

// A filled rectangle in window coordinates (rows from the top) through the scissor: no shaders,
// so the game runs on any OpenGL.
void fill(int window_h, int x, int y, int w, int h, float r, float g, float b) {
  if (w <= 0 || h <= 0) return;
  glScissor(x, window_h - y - h, w, h);
  glClearColor(r, g, b, 1);
  glClear(GL_COLOR_BUFFER_BIT);
}

// One eye: a background, bars at two depths moving with the frame (disparity of opposite signs in
// the two eyes), and the stamp band on top; only the stamp over a scene already drawn (`over_scene`).
void draw_eye(const Rect& eye, int window_h, long frame, double fps, int eye_sign, const nelf::FrameStamp& stamp,
              bool over_scene) {
  if (!over_scene) {
    fill(window_h, eye.x, eye.y, eye.w, eye.h, 0.16f, 0.18f, 0.24f);
    const double t = frame / fps;
    const int disparity = eye.w / 40;
    const int x_near = static_cast<int>((0.5 + 0.35 * std::sin(t * 1.3)) * eye.w * 0.8);
    const int x_far = static_cast<int>((0.5 + 0.35 * std::cos(t * 0.7)) * eye.w * 0.8);
    fill(window_h, eye.x + x_far - eye_sign * disparity / 2, eye.y + eye.h / 4, eye.w / 10, eye.h / 2, 0.2f, 0.55f,
         0.9f);
    fill(window_h, eye.x + x_near + eye_sign * disparity, eye.y + eye.h / 3, eye.w / 8, eye.h / 3, 0.95f, 0.45f, 0.2f);
  }
  const auto bits = nelf::stamp_bits(stamp);
  for (int i = 0; i < nelf::kStampBits; ++i) {
    const nelf::StampCell c = nelf::stamp_cell(i, eye.w, eye.h);
    const float v = bits[static_cast<std::size_t>(i)] ? 1.0f : 0.0f;
    fill(window_h, eye.x + c.x0, eye.y + c.y0, c.x1 - c.x0, c.y1 - c.y0, v, v, v);
  }
}

// A texture of coloured noise for the planes: texture is what a stereo match needs.
GLuint make_noise_texture() {
  constexpr int kSize = 128;
  std::vector<std::uint8_t> texels(kSize * kSize * 3);
  std::uint32_t state = 12345;
  for (std::uint8_t& t : texels) {
    state = state * 1664525u + 1013904223u;
    t = static_cast<std::uint8_t>(40 + (state >> 24) % 200);
  }
  GLuint texture = 0;
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_2D, texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, kSize, kSize, 0, GL_RGB, GL_UNSIGNED_BYTE, texels.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  return texture;
}

void textured_quad(double x0, double y0, double x1, double y1, double z, double s0, double t0, double s1, double t1) {
  glBegin(GL_QUADS);
  glTexCoord2d(s0, t0);
  glVertex3d(x0, y0, -z);
  glTexCoord2d(s1, t0);
  glVertex3d(x1, y0, -z);
  glTexCoord2d(s1, t1);
  glVertex3d(x1, y1, -z);
  glTexCoord2d(s0, t1);
  glVertex3d(x0, y1, -z);
  glEnd();
}

// One eye of --scene planes (planes_scene.hpp): the camera `eye_sign` half the eye separation to
// the right (+1) or left (−1), its frustum shifted so that both meet at the convergence distance.
void draw_planes(const Rect& eye, int window_h, int eye_sign, GLuint texture) {
  using namespace nelf::test_game;
  glViewport(eye.x, window_h - eye.y - eye.h, eye.w, eye.h);
  glScissor(eye.x, window_h - eye.y - eye.h, eye.w, eye.h);
  glClearColor(0, 0, 0, 1);
  glClearDepth(1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  const double half_w = kNearClip * half_fov_tangent(), half_h = half_w * eye.h / eye.w;
  const double camera_x = eye_sign * kEyeSeparation / 2, shift = -camera_x * kNearClip / kConvergence;
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glFrustum(-half_w + shift, half_w + shift, -half_h, half_h, kNearClip, kFarClip);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glTranslated(-camera_x, 0, 0);
  glEnable(GL_TEXTURE_2D);
  glBindTexture(GL_TEXTURE_2D, texture);
  glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_REPLACE);
  const double far_half = 1.5 * kFarPlane * half_fov_tangent();
  textured_quad(-far_half, -far_half, far_half, far_half, kFarPlane, 0, 0, 1, 1);
  textured_quad(kNearLeft, kNearBottom, kNearRight, kNearTop, kNearPlane, 0.5, 0.5, 1.0, 0.9);
  glDisable(GL_TEXTURE_2D);
  glDisable(GL_DEPTH_TEST);
}

// The quad of the HUD's bar, `shift` (a fraction of the window) to the right, in immediate mode.
void hud_bar(int w, int h, double shift) {
  using namespace nelf::test_game;
  glBegin(GL_QUADS);
  glVertex2d((kHudX0 + shift) * w, kHudTop * h);
  glVertex2d((kHudX1 + shift) * w, kHudTop * h);
  glVertex2d((kHudX1 + shift) * w, kHudBottom * h);
  glVertex2d((kHudX0 + shift) * w, kHudBottom * h);
  glEnd();
}

// --hud: drawn over both eyes at once (GL_BACK), in window coordinates, white (hud.hpp).
void draw_hud(Hud hud, int w, int h, GLuint list) {
  using namespace nelf::test_game;
  glDrawBuffer(GL_BACK);
  glViewport(0, 0, w, h);
  glScissor(0, 0, w, h);
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glOrtho(0, w, h, 0, -1, 1);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glColor3f(1, 1, 1);
  switch (hud) {
    case Hud::none:
      return;
    case Hud::arrays: {
      const GLfloat corners[] = {static_cast<GLfloat>(kHudX0 * w), static_cast<GLfloat>(kHudTop * h),
                                 static_cast<GLfloat>(kHudX1 * w), static_cast<GLfloat>(kHudTop * h),
                                 static_cast<GLfloat>(kHudX1 * w), static_cast<GLfloat>(kHudBottom * h),
                                 static_cast<GLfloat>(kHudX0 * w), static_cast<GLfloat>(kHudBottom * h)};
      glEnableClientState(GL_VERTEX_ARRAY);
      glVertexPointer(2, GL_FLOAT, 0, corners);
      glDrawArrays(GL_TRIANGLE_FAN, 0, 4);
      glDisableClientState(GL_VERTEX_ARRAY);
      return;
    }
    case Hud::immediate:
      hud_bar(w, h, 0);
      return;
    case Hud::list:
      // The list draws the bar and moves the matrix; the bar drawn after it lands kHudListShift right.
      glNewList(list, GL_COMPILE);
      hud_bar(w, h, 0);
      glTranslated(kHudListShift * w, 0, 0);
      glEndList();
      glCallList(list);
      hud_bar(w, h, 0);
      return;
    case Hud::copy:
      // The bar, then a copy of it kHudListShift to the right, read from GL_BACK (the left eye).
      hud_bar(w, h, 0);
      glRasterPos2d((kHudX0 + kHudListShift) * w, kHudBottom * h);
      glCopyPixels(static_cast<GLint>(kHudX0 * w), static_cast<GLint>(h - kHudBottom * h),
                   static_cast<GLsizei>((kHudX1 - kHudX0) * w), static_cast<GLsizei>((kHudBottom - kHudTop) * h),
                   GL_COLOR);
      return;
    case Hud::bitmap: {
      const std::vector<GLubyte> block(kHudBlock * kHudBlock / 8 * 4, 0xFF);  // rows padded to 4 bytes
      glRasterPos2d(kHudX0 * w, kHudBlockBottom * h);
      for (int i = 0; i < kHudBlocks; ++i) glBitmap(kHudBlock, kHudBlock, 0, 0, kHudBlockStep, 0, block.data());
      return;
    }
  }
}

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

void sleep_until_ns(std::int64_t t) {
  timespec ts{static_cast<time_t>(t / 1000000000LL), static_cast<long>(t % 1000000000LL)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR && !g_stop) {
  }
}

// The window and its context through one toolkit.
class GameWindow {
 public:
  virtual ~GameWindow() = default;
  virtual void framebuffer_size(int& w, int& h) = 0;
  virtual bool closed() = 0;  // polls events
  virtual void swap() = 0;
};

class GlfwGameWindow final : public GameWindow {
 public:
  GlfwGameWindow(const Options& o, int w, int h) {
    if (!glfwInit()) throw std::runtime_error("GLFW cannot start (no X display?)");
    glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
    glfwWindowHint(GLFW_STEREO, o.mode == Mode::quad_buffer ? GLFW_TRUE : GLFW_FALSE);
    window_ = glfwCreateWindow(w, h, o.title.c_str(), nullptr, nullptr);
    if (!window_) {
      glfwTerminate();
      throw std::runtime_error("GLFW cannot open a " + std::to_string(w) + "x" + std::to_string(h) + " OpenGL window" +
                               (o.mode == Mode::quad_buffer ? " with stereo buffers" : ""));
    }
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(o.swap_interval);  // 0: the game paces itself at --fps
  }
  ~GlfwGameWindow() override {
    glfwDestroyWindow(window_);
    glfwTerminate();
  }
  void framebuffer_size(int& w, int& h) override { glfwGetFramebufferSize(window_, &w, &h); }
  bool closed() override {
    glfwPollEvents();
    return glfwWindowShouldClose(window_);
  }
  void swap() override { glfwSwapBuffers(window_); }

 private:
  GLFWwindow* window_ = nullptr;
};

class SdlGameWindow final : public GameWindow {
 public:
  SdlGameWindow(const Options& o, int w, int h) {
    if (SDL_Init(SDL_INIT_VIDEO) != 0) throw std::runtime_error(std::string("SDL cannot start: ") + SDL_GetError());
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 2);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 1);
    SDL_GL_SetAttribute(SDL_GL_DOUBLEBUFFER, 1);
    SDL_GL_SetAttribute(SDL_GL_STEREO, o.mode == Mode::quad_buffer ? 1 : 0);
    window_ = SDL_CreateWindow(o.title.c_str(), SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, w, h,
                               SDL_WINDOW_OPENGL | SDL_WINDOW_RESIZABLE);
    if (!window_) {
      const std::string why = SDL_GetError();
      SDL_Quit();
      throw std::runtime_error("SDL cannot open an OpenGL window: " + why);
    }
    context_ = SDL_GL_CreateContext(window_);
    if (!context_) {
      const std::string why = SDL_GetError();
      SDL_DestroyWindow(window_);
      SDL_Quit();
      throw std::runtime_error("SDL cannot make an OpenGL context: " + why);
    }
    SDL_GL_SetSwapInterval(o.swap_interval);
  }
  ~SdlGameWindow() override {
    SDL_GL_DeleteContext(context_);
    SDL_DestroyWindow(window_);
    SDL_Quit();
  }
  void framebuffer_size(int& w, int& h) override { SDL_GL_GetDrawableSize(window_, &w, &h); }
  bool closed() override {
    SDL_Event e;
    while (SDL_PollEvent(&e))
      if (e.type == SDL_QUIT || (e.type == SDL_WINDOWEVENT && e.window.event == SDL_WINDOWEVENT_CLOSE)) closed_ = true;
    return closed_;
  }
  void swap() override { SDL_GL_SwapWindow(window_); }

 private:
  SDL_Window* window_ = nullptr;
  SDL_GLContext context_ = nullptr;
  bool closed_ = false;
};

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

int run(const Options& o) {
  std::unique_ptr<std::FILE, FileCloser> log;
  if (!o.log.empty()) {
    log.reset(std::fopen(o.log.c_str(), "w"));
    if (!log) throw std::runtime_error(o.log + ": cannot write the frame log");
    std::fputs("frame,present_ns\n", log.get());
  }
  int w = 0, h = 0;
  window_size(o, w, h);
  std::unique_ptr<GameWindow> window;
  GLuint texture = 0, hud_list = 0;
  const auto open_window = [&] {
    window.reset();  // the old one first: its toolkit is shut down and started again
    if (o.toolkit == Toolkit::glfw)
      window = std::make_unique<GlfwGameWindow>(o, w, h);
    else
      window = std::make_unique<SdlGameWindow>(o, w, h);
    glEnable(GL_SCISSOR_TEST);
    if (o.planes) texture = make_noise_texture();  // the new window's context has none
    if (o.hud == Hud::list) hud_list = glGenLists(1);
  };
  open_window();
  const auto period = static_cast<std::int64_t>(std::llround(1e9 / o.fps));
  const std::int64_t start = now_ns();
  std::int64_t deadline = start;
  for (long frame = 0; !g_stop; ++frame) {
    if (o.frames && frame >= o.frames) break;
    if (o.duration_s > 0 && static_cast<double>(now_ns() - start) >= o.duration_s * 1e9) break;
    if (window->closed()) break;
    if (o.reopen_after && frame == o.reopen_after) {
      window_size(o, w, h);
      open_window();
    }
    window->framebuffer_size(w, h);
    Rect left{}, right{};
    eye_rects(o.mode, w, h, left, right);
    if (o.mode == Mode::fp) fill(h, 0, 0, w, h, 0, 0, 0);  // the gap
    // The present time is taken last before drawing the stamp, right before the swap.
    const nelf::FrameStamp stamp{static_cast<std::uint32_t>(frame), now_ns()};
    // Quad-buffer stereo: each eye over the whole window, into its own back buffer.
    if (o.mode == Mode::quad_buffer) glDrawBuffer(GL_BACK_LEFT);
    if (o.planes) draw_planes(left, h, -1, texture);
    draw_eye(left, h, frame, o.fps, -1, stamp, o.planes);
    if (o.mode == Mode::quad_buffer) glDrawBuffer(GL_BACK_RIGHT);
    if (o.planes) draw_planes(right, h, +1, texture);
    draw_eye(right, h, frame, o.fps, +1, stamp, o.planes);
    if (o.hud != Hud::none) draw_hud(o.hud, w, h, hud_list);
    window->swap();
    if (log) std::fprintf(log.get(), "%ld,%lld\n", frame, static_cast<long long>(stamp.present_ns));
    deadline += period;
    const std::int64_t now = now_ns();
    if (now > deadline + period) deadline = now;  // fell behind: skip ahead rather than burst
    if (o.swap_interval == 0) sleep_until_ns(deadline);
  }
  return g_stop ? 0 : o.exit_status;
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    return run(parse(argc, argv));
  } catch (const BadUsage& e) {
    std::fprintf(stderr, "nelf-test-game: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nelf-test-game: %s\n", e.what());
    return 1;
  }
}
