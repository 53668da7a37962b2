#include "hmz_output/window_display.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hmz_output/glfw_window.hpp"

namespace nelf {

namespace {

// The packed frame in a desktop window (scaled to fit) or 1:1 fullscreen on a monitor; `f` switches.
class PackedWindowDisplay final : public glfw::WindowDisplay {
 public:
  PackedWindowDisplay(const DisplayOptions& options, WindowMode mode) : glfw::WindowDisplay(options) {
    glfw::WindowSetup setup;
    setup.shown_size = options.packed;
    if (mode == WindowMode::fullscreen) {
      setup.fullscreen = glfw::choose_monitor(options);
      if (!setup.fullscreen.monitor) throw std::runtime_error(setup.fullscreen.error);
      monitor_name_ = setup.fullscreen.info.name;
    }
    create(setup);
  }

  std::string toggle_fullscreen() override {
    GLFWwindow* window = this->window();
    const DisplayOptions& o = options();
    if (glfwGetWindowMonitor(window)) {
      const bool opened_fullscreen = windowed_size_[0] == 0;
      glfwSetWindowMonitor(window, nullptr, windowed_position_[0], windowed_position_[1],
                           opened_fullscreen ? o.packed[0] : windowed_size_[0],
                           opened_fullscreen ? o.packed[1] : windowed_size_[1], 0);
      if (opened_fullscreen) fit_to_work_area();
      monitor_name_.clear();
      refresh_hz_ = decide_refresh();
      return "window";
    }
    const glfw::ChosenMonitor chosen = glfw::choose_monitor(o);
    // On screen as one line: the first line of the error (the xrandr commands are in the log).
    if (!chosen.monitor) return chosen.error.substr(0, chosen.error.find('\n'));
    glfwGetWindowPos(window, &windowed_position_[0], &windowed_position_[1]);
    glfwGetWindowSize(window, &windowed_size_[0], &windowed_size_[1]);
    glfwSetWindowMonitor(window, chosen.monitor, 0, 0, o.packed[0], o.packed[1],
                         static_cast<int>(std::lround(chosen.info.refresh_hz)));
    monitor_name_ = chosen.info.name;
    refresh_hz_ = decide_refresh();
    return "fullscreen on " + chosen.info.name;
  }

 private:
  void draw_to_window(int fb_width, int fb_height) override {
    glDrawBuffer(GL_BACK);
    blit_fitted(0, 0, options().packed[0], options().packed[1], fb_width, fb_height);
    draw_caption(fb_width, fb_height);
  }

  std::string kind() const override {
    return glfwGetWindowMonitor(window()) != nullptr ? "fullscreen on " + monitor_name_ : std::string("window");
  }

  bool takes_preview_caption() const override { return true; }
  void set_preview_caption(PreviewCaption caption) override {
    caption_ = std::move(caption);
    caption_texture_ = {};
    caption_fbo_ = {};
    if (caption_.empty()) return;
    caption_texture_ = gl::make_texture_2d(GL_RGBA8, caption_.width, caption_.height);
    glTextureSubImage2D(caption_texture_.id(), 0, 0, 0, caption_.width, caption_.height, GL_RGBA, GL_UNSIGNED_BYTE,
                        caption_.rgba.data());
    caption_fbo_ = gl::make_framebuffer(caption_texture_);
    gl::check_error("uploading the preview caption");
  }

  // The caption over the picture, in a window only (fullscreen, the window is the HMD's signal).
  void draw_caption(int fb_width, int fb_height) const {
    if (caption_.empty() || glfwGetWindowMonitor(window()) != nullptr) return;
    const double scale = std::max(1.0, fb_height / 16.0 / caption_.height);
    int w = static_cast<int>(std::lround(caption_.width * scale));
    int h = static_cast<int>(std::lround(caption_.height * scale));
    if (w > fb_width * 0.95) {  // narrowed to fit, its aspect kept
      h = static_cast<int>(std::lround(h * (fb_width * 0.95) / w));
      w = static_cast<int>(std::lround(fb_width * 0.95));
    }
    const int x0 = (fb_width - w) / 2, y0 = fb_height / 12;  // GL's rows count from the bottom
    // The caption's row 0 is its top: flipped on the way, as blit_fitted flips the packed frame.
    glBlitNamedFramebuffer(caption_fbo_.id(), 0, 0, 0, caption_.width, caption_.height, x0, y0 + h, x0 + w, y0,
                           GL_COLOR_BUFFER_BIT, GL_LINEAR);
  }

  std::string monitor_name_;
  PreviewCaption caption_;
  gl::Texture caption_texture_;
  gl::Framebuffer caption_fbo_;
};

}  // namespace

std::unique_ptr<Display> open_window_display(const DisplayOptions& options, WindowMode mode) {
  return std::make_unique<PackedWindowDisplay>(options, mode);
}

}  // namespace nelf
