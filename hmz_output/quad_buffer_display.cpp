// `--output quad-buffer` (DESIGN.md §7): an OpenGL quad-buffer stereo window, each eye's area of the
// packed frame blitted into its own back buffer (GL_BACK_LEFT, GL_BACK_RIGHT), for drivers and
// shutter-glasses or HMD setups that take stereo that way (NVIDIA with Option "Stereo"; Mesa never).
#include <fmt/format.h>

#include <array>
#include <stdexcept>

#include "hmz_output/glfw_window.hpp"
#include "hmz_output/packing.hpp"

namespace nelf {

namespace {

std::string quad_buffer_advice(const std::string& why) {
  return "quad-buffer: the OpenGL driver offers no stereo visuals (" + why +
         "); quad-buffer stereo needs e.g. an NVIDIA Quadro/RTX with Option \"Stereo\" \"12\" in the X "
         "configuration (Mesa never offers it); use --output fullscreen or --output kms";
}

// One eye's image in the packed frame of options.packed.
std::array<int, 2> eye_size(const DisplayOptions& options) {
  switch (options.signal.kind) {
    case SignalKind::hdmi_frame_packing:
      return {options.signal.eye_width, options.signal.eye_height};
    case SignalKind::side_by_side:
      return {options.packed[0] / 2, options.packed[1]};
    case SignalKind::top_bottom:
      return {options.packed[0], options.packed[1] / 2};
    case SignalKind::single_eye:
      break;
  }
  return {0, 0};
}

// Where each back buffer's eye is in the packed frame.
std::array<EyeArea, 2> both_eye_areas(const DisplayOptions& options) {
  if (options.packed[0] <= 0 || options.packed[1] <= 0) return {};  // refused as an empty packed frame
  const auto eye = eye_size(options);
  const PackedLayout layout = packed_layout(options.signal, eye);
  if (!layout.areas[0] || !layout.areas[1] || eye[0] <= 0 || eye[1] <= 0)
    throw std::invalid_argument(
        fmt::format("quad-buffer needs a signal carrying both eyes (not {})", options.signal.name));
  return {*layout.areas[0], *layout.areas[1]};
}

class QuadBufferDisplay final : public glfw::WindowDisplay {
 public:
  // The signal is checked first, before GLFW starts (without a display too).
  explicit QuadBufferDisplay(const DisplayOptions& options) : QuadBufferDisplay(options, both_eye_areas(options)) {}
  QuadBufferDisplay(const DisplayOptions& options, std::array<EyeArea, 2> eye_areas)
      : glfw::WindowDisplay(options), eye_areas_(eye_areas) {
    glfw::WindowSetup setup;
    // Each back buffer shows one eye: the window is an eye's size.
    setup.shown_size = eye_size(options);
    setup.stereo = true;
    setup.no_visual_advice = quad_buffer_advice;
    create(setup);
  }

  std::string toggle_fullscreen() override { return "fullscreen is not available on a quad-buffer output"; }

 private:
  void draw_to_window(int fb_width, int fb_height) override {
    const std::array<GLenum, 2> buffers{GL_BACK_LEFT, GL_BACK_RIGHT};
    for (int eye = 0; eye < 2; ++eye) {
      glDrawBuffer(buffers[eye]);
      const EyeArea& a = eye_areas_[eye];
      blit_fitted(a.x, a.y, a.width, a.height, fb_width, fb_height);
    }
    glDrawBuffer(GL_BACK);
  }

  std::string kind() const override { return "quad-buffer window"; }

  const std::array<EyeArea, 2> eye_areas_;  // what each back buffer shows
};

}  // namespace

std::unique_ptr<Display> open_quad_buffer_display(const DisplayOptions& options) {
  return std::make_unique<QuadBufferDisplay>(options);
}

}  // namespace nelf
