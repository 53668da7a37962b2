#include "hmz_output/glfw_window.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <utility>

#include "core/gl/egl_context.hpp"
#include "hmz_output/glfw_x11.hpp"
#include "hmz_output/swap_timing.hpp"

namespace nelf::glfw {

namespace {

// GLFW reports errors through a callback; the last description (on the main thread, where every
// GLFW call happens) becomes part of our exception messages.
std::string& last_glfw_error() {
  static std::string text;
  return text;
}

int last_glfw_error_code = 0;

void on_glfw_error(int code, const char* description) {
  last_glfw_error_code = code;
  last_glfw_error() = description ? description : "unknown error";
}

std::string take_glfw_error() {
  std::string text = last_glfw_error().empty() ? std::string("no description") : last_glfw_error();
  last_glfw_error().clear();
  return text;
}

std::string no_display_advice() { return "run inside a desktop session, under xvfb-run, or use --output kms"; }

}  // namespace

// glfwInit/glfwTerminate, shared by every open window: GLFW is process-global, and terminating it
// when the last window goes lets a later display connect to another X server (DISPLAY is read at
// init).
class Library {
 public:
  static std::shared_ptr<Library> acquire() {
    static std::weak_ptr<Library> current;
    if (auto existing = current.lock()) return existing;
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) throw std::runtime_error("no display: DISPLAY is not set; " + no_display_advice());
    glfwSetErrorCallback(on_glfw_error);
    last_glfw_error().clear();
    if (!glfwInit()) {
      const std::string why = take_glfw_error();
      if (why.find("open display") != std::string::npos || why.find("Failed to open") != std::string::npos)
        throw std::runtime_error(fmt::format("no display: cannot connect to the X server at DISPLAY={} ({}); {}",
                                             display, why, no_display_advice()));
      throw std::runtime_error("GLFW cannot start on DISPLAY=" + std::string(display) + ": " + why +
                               "; check the X session, or use --output kms");
    }
    survive_x_connection_loss();
    auto library = std::shared_ptr<Library>(new Library());
    current = library;
    return library;
  }
  ~Library() { glfwTerminate(); }
  Library(const Library&) = delete;
  Library& operator=(const Library&) = delete;

 private:
  Library() = default;
};

namespace {

MonitorInfo describe(GLFWmonitor* monitor) {
  MonitorInfo info;
  const char* name = glfwGetMonitorName(monitor);
  info.name = name ? name : "unnamed";
  info.model = glfw_monitor_model(monitor);
  if (const GLFWvidmode* mode = glfwGetVideoMode(monitor)) {
    info.width = mode->width;
    info.height = mode->height;
    info.refresh_hz = mode->refreshRate;
  }
  return info;
}

std::optional<KeyPress::Named> named_key(int key) {
  using N = KeyPress::Named;
  switch (key) {
    case GLFW_KEY_SPACE:
      return N::space;
    case GLFW_KEY_LEFT:
      return N::left;
    case GLFW_KEY_RIGHT:
      return N::right;
    case GLFW_KEY_UP:
      return N::up;
    case GLFW_KEY_DOWN:
      return N::down;
    case GLFW_KEY_PAGE_UP:
      return N::page_up;
    case GLFW_KEY_PAGE_DOWN:
      return N::page_down;
    case GLFW_KEY_ESCAPE:
      return N::escape;
    case GLFW_KEY_ENTER:
    case GLFW_KEY_KP_ENTER:
      return N::enter;
    case GLFW_KEY_TAB:
      return N::tab;
    case GLFW_KEY_BACKSPACE:
      return N::backspace;
    default:
      return std::nullopt;
  }
}

}  // namespace

ChosenMonitor choose_monitor(const DisplayOptions& options) {
  int count = 0;
  GLFWmonitor** monitors = glfwGetMonitors(&count);
  std::vector<MonitorInfo> infos;
  for (int i = 0; i < count; ++i) infos.push_back(describe(monitors[i]));
  const MonitorChoice choice = nelf::choose_monitor(infos, options.monitor, options.packed, options.signal);
  if (!choice.index) return {nullptr, {}, choice.error};
  return {monitors[*choice.index], infos[*choice.index], {}};
}

// Owns the GLFW window, and with it the GL context (a window's context dies with the window).
class WindowContext final : public gl::Context {
 public:
  WindowContext(std::shared_ptr<Library> library, GLFWwindow* window) : library_(std::move(library)), window_(window) {
    glfwMakeContextCurrent(window_);
    const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    renderer_ = renderer ? renderer : "unknown renderer";
    software_ = gl::is_software_renderer(renderer_);
  }
  ~WindowContext() override { glfwDestroyWindow(window_); }
  WindowContext(const WindowContext&) = delete;
  WindowContext& operator=(const WindowContext&) = delete;

  void make_current() const override {
    glfwMakeContextCurrent(window_);
    if (glfwGetCurrentContext() != window_)
      throw gl::GlError("cannot make the window's OpenGL context current: " + take_glfw_error());
  }
  const std::string& renderer() const override { return renderer_; }
  bool is_software() const override { return software_; }
  GLFWwindow* window() const { return window_; }

 private:
  std::shared_ptr<Library> library_;  // outlives the window
  GLFWwindow* window_;
  std::string renderer_;
  bool software_ = false;
};

namespace {

// Maps the window and waits (up to 2 s) until the X server shows it: GLFW waits only 0.1 s, and a
// frame swapped into a window that is not yet viewable is lost.
void show(GLFWwindow* window) {
  glfwShowWindow(window);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (!glfwGetWindowAttrib(window, GLFW_VISIBLE) && std::chrono::steady_clock::now() < deadline)
    glfwWaitEventsTimeout(0.01);
}

WindowDisplay* self(GLFWwindow* window) { return static_cast<WindowDisplay*>(glfwGetWindowUserPointer(window)); }

}  // namespace

WindowDisplay::WindowDisplay(const DisplayOptions& options) : options_(options) {
  if (options.packed[0] <= 0 || options.packed[1] <= 0)
    throw std::invalid_argument(
        fmt::format("window display: empty packed frame {}x{}", options.packed[0], options.packed[1]));
  library_ = Library::acquire();
  display_name_ = std::getenv("DISPLAY");
}

void WindowDisplay::create(const WindowSetup& setup) {
  shown_size_ = setup.shown_size;
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_NATIVE_CONTEXT_API);  // GLX: its EGL refuses stereo
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_DEPTH_BITS, 0);
  glfwWindowHint(GLFW_STENCIL_BITS, 0);
  glfwWindowHint(GLFW_STEREO, setup.stereo ? GLFW_TRUE : GLFW_FALSE);
  // Losing focus must not minimise the HMD's picture (the user types on the other monitor).
  glfwWindowHint(GLFW_AUTO_ICONIFY, GLFW_FALSE);
  glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);  // sized first, shown after

  GLFWmonitor* monitor = setup.fullscreen.monitor;
  // The monitor's current mode already is the packed size (choose_monitor checked), so asking for
  // exactly that mode keeps GLFW from switching modes.
  if (monitor) glfwWindowHint(GLFW_REFRESH_RATE, static_cast<int>(std::lround(setup.fullscreen.info.refresh_hz)));

  last_glfw_error().clear();
  last_glfw_error_code = 0;
  GLFWwindow* window = glfwCreateWindow(shown_size_[0], shown_size_[1], options_.title.c_str(), monitor, nullptr);
  if (!window) throw_creation_error(setup);
  context_ = std::make_shared<WindowContext>(library_, window);
  glfwSetWindowUserPointer(window, this);
  glfwSetKeyCallback(window, on_key);
  glfwSetCharCallback(window, on_char);

  if (!monitor) fit_to_work_area();
  show(window);

  packed_texture_ = gl::make_bgra8_texture_2d(options_.packed[0], options_.packed[1]);
  packed_fbo_ = gl::make_framebuffer(packed_texture_);
  const GLfloat black[4] = {0.f, 0.f, 0.f, 1.f};
  glClearNamedFramebufferfv(packed_fbo_.id(), GL_COLOR, 0, black);

  if (setup.stereo) {
    GLboolean stereo = GL_FALSE;
    glGetBooleanv(GL_STEREO, &stereo);
    if (!stereo) throw std::runtime_error(setup.no_visual_advice("the window has no stereo buffers"));
  }

  refresh_hz_ = decide_refresh();
  vsync_ = decide_vsync();
  gl::check_error("opening the window display");
}

WindowDisplay::~WindowDisplay() {
  if (!context_) return;  // create() never made the window
  // The GL objects die while their context is current; the context (and window) after them.
  try {
    context_->make_current();
  } catch (...) {
  }
  // The window may outlive this display (a compositor still holds context()): no more callbacks here.
  glfwSetWindowUserPointer(context_->window(), nullptr);
  glfwSetKeyCallback(context_->window(), nullptr);
  glfwSetCharCallback(context_->window(), nullptr);
  packed_fbo_.reset();
  packed_texture_.reset();
}

std::shared_ptr<gl::Context> WindowDisplay::context() const { return context_; }

GLFWwindow* WindowDisplay::window() const { return context_->window(); }

void WindowDisplay::present() {
  throw_if_connection_lost();
  GLFWwindow* window = context_->window();
  int fb_width = 0, fb_height = 0;
  glfwGetFramebufferSize(window, &fb_width, &fb_height);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glDisable(GL_SCISSOR_TEST);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  draw_to_window(fb_width, fb_height);
  gl::check_error("presenting the packed frame");
  glfwSwapBuffers(window);
  throw_if_connection_lost();
}

std::vector<KeyPress> WindowDisplay::poll_events() {
  throw_if_connection_lost();
  glfwPollEvents();
  throw_if_connection_lost();
  return std::exchange(pending_keys_, {});
}

bool WindowDisplay::close_requested() const { return x_connection_lost() || glfwWindowShouldClose(context_->window()); }

std::string WindowDisplay::description() const {
  return fmt::format("{} {}x{} on {} ({}, {}, {:g} Hz)", kind(), options_.packed[0], options_.packed[1], display_name_,
                     context_->renderer(), vsync_ ? "vsync" : "no vsync", refresh_hz_);
}

void WindowDisplay::throw_if_connection_lost() const {
  if (x_connection_lost())
    throw std::runtime_error("lost the connection to the X server at DISPLAY=" + display_name_ +
                             " (it exited or the session ended); the window is gone");
}

void WindowDisplay::throw_creation_error(const WindowSetup& setup) {
  const std::string why = take_glfw_error();
  if (setup.no_visual_advice && last_glfw_error_code == GLFW_FORMAT_UNAVAILABLE)
    throw std::runtime_error(setup.no_visual_advice(why));
  if (last_glfw_error_code == GLFW_VERSION_UNAVAILABLE || last_glfw_error_code == GLFW_API_UNAVAILABLE)
    throw std::runtime_error("OpenGL 4.5 core is not available on this X display (" + why +
                             "); update the graphics driver or Mesa, or use --output kms");
  throw std::runtime_error("cannot open a window: " + why);
}

void WindowDisplay::fit_to_work_area() {
  GLFWwindow* window = context_->window();
  GLFWmonitor* primary = glfwGetPrimaryMonitor();
  if (!primary) return;
  int area_x = 0, area_y = 0, area_w = 0, area_h = 0;
  glfwGetMonitorWorkarea(primary, &area_x, &area_y, &area_w, &area_h);
  int left = 0, top = 0, right = 0, bottom = 0;
  glfwGetWindowFrameSize(window, &left, &top, &right, &bottom);
  const int room_w = area_w - left - right, room_h = area_h - top - bottom;
  if (room_w <= 0 || room_h <= 0) return;
  const double scale =
      std::min({1.0, static_cast<double>(room_w) / shown_size_[0], static_cast<double>(room_h) / shown_size_[1]});
  const int w = std::max(1, static_cast<int>(std::floor(shown_size_[0] * scale)));
  const int h = std::max(1, static_cast<int>(std::floor(shown_size_[1] * scale)));
  glfwSetWindowSize(window, w, h);
  glfwSetWindowPos(window, area_x + left + (room_w - w) / 2, area_y + top + (room_h - h) / 2);
  windowed_size_ = {w, h};
  windowed_position_ = {area_x + left + (room_w - w) / 2, area_y + top + (room_h - h) / 2};
}

// The default framebuffer's row 0 is the bottom one, the packed frame's its top row. On llvmpipe
// the window's buffer is stored top row first, so at 1:1 this flip is none in memory and, the
// packed texture being BGRA like the window, the blit is a memcpy: 0.7–1 ms for 1280x1470 instead
// of a 5 ms shader pass (~10 ms of CPU on its two threads). Scaled, it is a shader pass.
void WindowDisplay::blit_fitted(int sx, int sy, int sw, int sh, int width, int height) const {
  if (width <= 0 || height <= 0) return;  // minimised
  const double scale = std::min(static_cast<double>(width) / sw, static_cast<double>(height) / sh);
  const int w = std::clamp(static_cast<int>(std::lround(sw * scale)), 1, width);
  const int h = std::clamp(static_cast<int>(std::lround(sh * scale)), 1, height);
  const int x0 = (width - w) / 2, y0 = (height - h) / 2;
  // Black bars only where there are any: on llvmpipe a full clear costs a tenth of the blit.
  if (w != width || h != height) {
    const GLfloat black[4] = {0.f, 0.f, 0.f, 1.f};
    glClearBufferfv(GL_COLOR, 0, black);
  }
  const GLenum filter = (w == sw && h == sh) ? GL_NEAREST : GL_LINEAR;
  glBlitNamedFramebuffer(packed_fbo_.id(), 0, sx, sy, sx + sw, sy + sh, x0, y0 + h, x0 + w, y0, GL_COLOR_BUFFER_BIT,
                         filter);
}

double WindowDisplay::decide_refresh() const {
  GLFWmonitor* monitor = glfwGetWindowMonitor(context_->window());
  if (!monitor) monitor = glfwGetPrimaryMonitor();
  if (monitor)
    if (const GLFWvidmode* mode = glfwGetVideoMode(monitor); mode && mode->refreshRate > 0) return mode->refreshRate;
  if (options_.signal.timing) return options_.signal.timing->refresh_hz();
  return 60.0;
}

// Whether glfwSwapBuffers really waits for the vertical blank. A software rasteriser never does
// (llvmpipe copies the image into the window with XPutImage/MIT-SHM; Xvfb has no vblank at all),
// nor a driver without a GLX swap-control extension. Otherwise: interval 1, and six swaps timed
// (after two to warm up); swaps_wait_for_vblank judges them. Costs about 8 frames at start-up.
bool WindowDisplay::decide_vsync() {
  const bool has_swap_control = glfwExtensionSupported("GLX_EXT_swap_control") ||
                                glfwExtensionSupported("GLX_MESA_swap_control") ||
                                glfwExtensionSupported("GLX_SGI_swap_control");
  if (context_->is_software() || !has_swap_control) {
    glfwSwapInterval(0);
    return false;
  }
  glfwSwapInterval(1);
  GLFWwindow* window = context_->window();
  const GLfloat black[4] = {0.f, 0.f, 0.f, 1.f};
  std::vector<double> intervals;
  auto last = std::chrono::steady_clock::now();
  for (int i = 0; i < 8; ++i) {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glClearBufferfv(GL_COLOR, 0, black);
    glfwSwapBuffers(window);
    glFinish();
    const auto now = std::chrono::steady_clock::now();
    if (i >= 2) intervals.push_back(std::chrono::duration<double>(now - last).count());  // skip warm-up
    last = now;
  }
  const bool waits = swaps_wait_for_vblank(intervals, refresh_hz_);
  if (!waits) glfwSwapInterval(0);
  return waits;
}

void WindowDisplay::on_key(GLFWwindow* window, int key, int /*scancode*/, int action, int mods) {
  WindowDisplay* display = self(window);
  if (!display || action == GLFW_RELEASE) return;
  display->last_mods_ = mods;
  KeyPress press;
  if (const auto named = named_key(key)) {
    press = KeyPress::of(*named);
  } else if (mods & (GLFW_MOD_CONTROL | GLFW_MOD_ALT)) {
    // With Ctrl or Alt held no character is typed; report the key's printable name instead.
    const char* name = glfwGetKeyName(key, 0);
    if (!name || !name[0] || name[1]) return;
    press = KeyPress::of(static_cast<char32_t>(static_cast<unsigned char>(name[0])));
  } else {
    return;  // printable: arrives through on_char as the character typed
  }
  press.shift = mods & GLFW_MOD_SHIFT;
  press.ctrl = mods & GLFW_MOD_CONTROL;
  press.alt = mods & GLFW_MOD_ALT;
  display->pending_keys_.push_back(press);
}

void WindowDisplay::on_char(GLFWwindow* window, unsigned int codepoint) {
  WindowDisplay* display = self(window);
  if (!display || codepoint == ' ') return;  // reported as Named::space by on_key
  KeyPress press = KeyPress::of(static_cast<char32_t>(codepoint));
  press.shift = display->last_mods_ & GLFW_MOD_SHIFT;
  display->pending_keys_.push_back(press);
}

}  // namespace nelf::glfw
