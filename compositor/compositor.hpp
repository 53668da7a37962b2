#pragma once
// The compositor stage: a stereo pair of views in, one image per eye at panel resolution out
// (DESIGN.md §3–4). Implementations: the OpenGL path (gl_compositor) and the CPU reference.
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/image.hpp"
#include "optics/profile.hpp"

namespace nelf {

class DisparitySurface;  // optics/depth.hpp

// Where the content's depth comes from (`--depth`): off, the flat emulated screen for everything;
// auto, the depth a frame carries (StereoVideoFrame::disparity: a synthetic scene's exact depth),
// estimated from the two views for frames without it; estimate, always estimated from the two views
// (inputs/stereo_matcher), even where the source knows better. The compositor composites with
// whatever disparity a frame carries; the player attaches the estimate (the compositor never matches).
enum class DepthMode { off, automatic, estimate };
// The names `--depth` takes, in order, and the mode of one (nothing for an unknown name).
const std::vector<std::string>& depth_mode_names();
std::optional<DepthMode> parse_depth_mode(std::string_view name);
std::string_view depth_mode_name(DepthMode mode);

struct CompositorOptions {
  // 0: one bilinear tap (comparison only); 1: footprint prefilter (default);
  // 4, 16: prefilter plus N aperture sub-samples per pixel.
  int fsaa = 1;
  // EGL device index for the GL compositor (`--gpu N`); unset: NELF_GPU, else the first hardware
  // device, else Mesa's software renderer.
  std::optional<int> gpu;
  DepthMode depth = DepthMode::off;
  // Hide the dead and stuck pixels of the profile's defect map (correction.defect_map) with the
  // other pixels of their ray bundles (optics/defect_compensation.hpp); `--no-defect-compensation`
  // shows them as they are, to compare. Without a map there is nothing to do either way.
  bool defect_compensation = true;
};

// Throws std::invalid_argument naming the allowed values when `fsaa` is not 0, 1, 4 or 16.
void validate_fsaa(int fsaa);

class Compositor {
 public:
  virtual ~Compositor() = default;
  // Renders both eyes' images for `views`. Each view's display_aspect sets the screen's aspect.
  virtual EyeImages compose(const StereoPair& views) = 0;
  // The content's depth for `eye`'s next compose() calls: each display pixel then shows the view
  // where its ray meets that surface rather than the flat screen (optics/depth.hpp). Null: the flat
  // screen. Stock profiles (no lenslets) keep the flat view.
  virtual void set_depth(Eye eye, std::shared_ptr<const DisparitySurface> surface) = 0;
};

}  // namespace nelf
