#pragma once
// The built-in demo source `synthetic:`: a short stereo clip rendered by nelf itself, so that the
// whole pipeline can be shown and tested without any media file. The scenes are deterministic
// (fixed seed), with a 440 Hz tone as audio:
// - `scene=spheres` (the default): a checkered wall far behind the emulated screen, spheres moving
//   at depths in front of, on and behind the screen plane;
// - `scene=planes`: a textured plane at `near` mm (default 250) in front of a textured plane at
//   `far` mm (default 1000), each covering a known region of the view (issue #15's oracle).
// Both know their exact depth: disparity() gives it per view pixel, regions() names the planes.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "core/view_disparity.hpp"
#include "optics/profile.hpp"

namespace nelf {

enum class SyntheticScene { spheres, planes };

// A part of the scene at one known depth, as the source's views show it: `mask` per view pixel
// (row-major, the view's size; 1 where the region is the front-most surface).
struct SceneRegion {
  std::string name;  // "near", "far"
  double depth_mm = 0;
  std::vector<std::uint8_t> left_mask, right_mask;
};

struct SyntheticClipSettings {
  SyntheticScene scene = SyntheticScene::spheres;
  double near_mm = 250.0;  // planes: the near plane's distance from the eyes
  double far_mm = 1000.0;  // planes: the far plane's
  // The stereo camera (screen_distance_mm, ipd_mm, horizontal_fov_deg below) was given in the
  // spec (`screen=`, `ipd=`, `fov=`): matched_to_display() then leaves it as it is.
  bool camera_given = false;
  int eye_width = 960;  // each view; the clip is full side-by-side in spirit but delivered as a pair
  int eye_height = 540;
  int fps = 24;
  double duration_s = 3.0;
  int audio_rate = 48000;
  double screen_distance_mm = 1000.0;  // zero parallax plane of the virtual stereo camera
  double ipd_mm = 63.0;
  double horizontal_fov_deg = 40.0;
};

// Parses "synthetic:" with optional options, e.g. "synthetic:duration=2,size=640x360,fps=30" or
// "synthetic:scene=planes,near=400" (keys: duration, fps, size, scene, near, far, screen, ipd, fov).
// Throws std::invalid_argument with the offending option on a bad spec.
SyntheticClipSettings parse_synthetic_spec(const std::string& spec);
bool is_synthetic_spec(const std::string& input);

// The camera that films the scene for `display`: its zero-parallax distance, the screen's angular
// width and the IPD of the lens-array eye's emulated screen (optics/depth.hpp's DepthGeometry for
// the clip's aspect), so that a point the scene puts at Z mm is shown at Z mm from the viewer's
// pupils. Unchanged when camera_given, or for a stock display (no lens array: nothing to match).
SyntheticClipSettings matched_to_display(SyntheticClipSettings settings, const Profile& display);

class SyntheticClip {
 public:
  explicit SyntheticClip(SyntheticClipSettings settings);
  const SyntheticClipSettings& settings() const { return settings_; }
  int frame_count() const;
  // The stereo pair at frame `index` (0 ≤ index < frame_count()), timestamp index / fps.
  StereoPair render(int index) const;
  // The exact disparity of both views at frame `index` (view pixels, core/view_disparity.hpp's
  // sign convention; DisparityOrigin::known), from the depth of the surface each pixel shows.
  std::shared_ptr<const StereoDisparity> disparity(int index) const;
  // The scene's regions of known depth at frame `index`: planes gives "near" and "far"; spheres none.
  std::vector<SceneRegion> regions(int index) const;
  // Mono audio samples (−1..1) for [first, first + count) at settings().audio_rate.
  std::vector<float> audio(std::int64_t first, int count) const;

 private:
  struct Sphere {
    double x, y, z, radius;  // mm, z from the viewer
    double swing_x, swing_z, phase;
    Rgba colour;
  };
  // The front-most surface a ray from the eye at (eye_x_mm, 0, 0) through `screen` (mm on the
  // zero-parallax screen) meets: its colour and its distance z.
  struct Surface {
    Rgba colour;
    double z;
  };
  double screen_width_mm() const;
  Vec2 screen_point_mm(double x, double y) const;
  std::vector<Sphere> spheres_at(double t) const;
  Surface surface(const std::vector<Sphere>& now, double eye_x_mm, Vec2 screen) const;
  Image render_eye(double eye_x_mm, double t, int samples) const;
  std::vector<double> depth_mm(double eye_x_mm, double t) const;  // per view pixel centre
  SyntheticClipSettings settings_;
  std::vector<Sphere> spheres_;
  StereoPair planes_pair_;  // the planes scene is still: rendered once
};

}  // namespace nelf
