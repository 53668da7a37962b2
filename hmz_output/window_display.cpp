#include "hmz_output/window_display.hpp"

#include <fmt/format.h>

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
  }

  std::string kind() const override {
    return glfwGetWindowMonitor(window()) != nullptr ? "fullscreen on " + monitor_name_ : std::string("window");
  }

  std::string monitor_name_;
};

}  // namespace

std::unique_ptr<Display> open_window_display(const DisplayOptions& options, WindowMode mode) {
  return std::make_unique<PackedWindowDisplay>(options, mode);
}

}  // namespace nelf
