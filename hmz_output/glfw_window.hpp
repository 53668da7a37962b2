#pragma once
// What the GLFW outputs share (window_display.cpp: window and fullscreen; quad_buffer_display.cpp):
// GLFW's lifetime, the window and its GL context, the packed framebuffer, key events, vsync and
// refresh detection, and the fitted blit. Each output is a subclass that says what the window shows
// (create()) and how a packed frame reaches it (draw_to_window()).
#include <epoxy/gl.h>
// After epoxy: GLFW must not include the system GL header.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/gl/objects.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/monitor_selection.hpp"

namespace nelf::glfw {

class Library;
class WindowContext;

struct ChosenMonitor {
  GLFWmonitor* monitor = nullptr;
  MonitorInfo info;
  std::string error;
};
// The monitor options.monitor names (monitor_selection.hpp's rules); needs GLFW started.
ChosenMonitor choose_monitor(const DisplayOptions& options);

// How create() makes the window.
struct WindowSetup {
  std::array<int, 2> shown_size{0, 0};  // what the window shows 1:1
  bool stereo = false;                  // quad-buffer visuals (GLFW_STEREO)
  ChosenMonitor fullscreen;             // fullscreen on this monitor (at its current mode), else windowed
  // The one-line error when the driver has no visual of the kind asked for (GLFW_FORMAT_UNAVAILABLE),
  // given GLFW's own reason; empty: the generic message.
  std::function<std::string(const std::string& why)> no_visual_advice;
};

class WindowDisplay : public Display {
 public:
  ~WindowDisplay() override;

  std::shared_ptr<gl::Context> context() const override;
  GLuint packed_framebuffer() const override { return packed_fbo_.id(); }
  GLuint packed_texture() const override { return packed_texture_.id(); }
  std::array<int, 2> packed_size() const override { return options_.packed; }
  void present() override;
  double refresh_hz() const override { return refresh_hz_; }
  bool vsync() const override { return vsync_; }
  std::vector<KeyPress> poll_events() override;
  bool close_requested() const override;
  std::string description() const override;

 protected:
  // Starts GLFW (throws the no-display errors); create() then makes the window.
  explicit WindowDisplay(const DisplayOptions& options);
  void create(const WindowSetup& setup);

  // Draws the packed frame into the window's default framebuffer (fb_width × fb_height), bound
  // for drawing; present() swaps after it.
  virtual void draw_to_window(int fb_width, int fb_height) = 0;
  // What description() begins with: "window", "fullscreen on HMZ-T1", "quad-buffer window".
  virtual std::string kind() const = 0;

  // Blits the packed rectangle (sx, sy, sw, sh) to the bound draw buffer, scaled to fit a
  // width × height framebuffer with its aspect kept, and flipped (see the .cpp).
  void blit_fitted(int sx, int sy, int sw, int sh, int width, int height) const;
  // Sizes the window to the largest multiple of what it shows that fits the primary monitor's
  // work area (never above 1:1), centred.
  void fit_to_work_area();
  double decide_refresh() const;

  GLFWwindow* window() const;
  const DisplayOptions& options() const { return options_; }
  std::array<int, 2> windowed_position_{0, 0};
  std::array<int, 2> windowed_size_{0, 0};  // 0×0: opened fullscreen, never windowed
  double refresh_hz_ = 60.0;

 private:
  bool decide_vsync();
  void throw_if_connection_lost() const;
  [[noreturn]] void throw_creation_error(const WindowSetup& setup);
  static void on_key(GLFWwindow* window, int key, int scancode, int action, int mods);
  static void on_char(GLFWwindow* window, unsigned int codepoint);

  DisplayOptions options_;
  std::shared_ptr<Library> library_;
  std::string display_name_;
  std::shared_ptr<WindowContext> context_;
  gl::Texture packed_texture_;
  gl::Framebuffer packed_fbo_;
  std::array<int, 2> shown_size_{0, 0};
  bool vsync_ = false;
  int last_mods_ = 0;
  std::vector<KeyPress> pending_keys_;
};

}  // namespace nelf::glfw
