#pragma once
// The built-in demo source `synthetic:`: a short stereo clip rendered by nelf itself, so that the
// whole pipeline can be shown and tested without any media file. The scene is deterministic (fixed
// seed): a checkered wall far behind the emulated screen, spheres moving at depths in front of, on
// and behind the screen plane, and a 440 Hz tone as audio.
#include <cstdint>
#include <string>
#include <vector>

#include "core/image.hpp"

namespace nelf {

struct SyntheticClipSettings {
  int eye_width = 960;  // each view; the clip is full side-by-side in spirit but delivered as a pair
  int eye_height = 540;
  int fps = 24;
  double duration_s = 3.0;
  int audio_rate = 48000;
  double screen_distance_mm = 1000.0;  // zero parallax plane of the virtual stereo camera
  double ipd_mm = 63.0;
  double horizontal_fov_deg = 40.0;
};

// Parses "synthetic:" with optional options, e.g. "synthetic:duration=2,size=640x360,fps=30".
// Throws std::invalid_argument with the offending option on a bad spec.
SyntheticClipSettings parse_synthetic_spec(const std::string& spec);
bool is_synthetic_spec(const std::string& input);

class SyntheticClip {
 public:
  explicit SyntheticClip(SyntheticClipSettings settings);
  const SyntheticClipSettings& settings() const { return settings_; }
  int frame_count() const;
  // The stereo pair at frame `index` (0 ≤ index < frame_count()), timestamp index / fps.
  StereoPair render(int index) const;
  // Mono audio samples (−1..1) for [first, first + count) at settings().audio_rate.
  std::vector<float> audio(std::int64_t first, int count) const;

 private:
  struct Sphere {
    double x, y, z, radius;  // mm, z from the viewer
    double swing_x, swing_z, phase;
    Rgba colour;
  };
  Image render_eye(double eye_x_mm, double t) const;
  SyntheticClipSettings settings_;
  std::vector<Sphere> spheres_;
};

}  // namespace nelf
