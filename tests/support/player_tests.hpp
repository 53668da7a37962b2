#pragma once
// Shared pieces of the player's tests (tests/player/gl on the offscreen output, tests/player/window
// on a real window): the test clip, the small panel's options, reading the eyes' panels back.
#include <algorithm>
#include <array>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/image.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/packing.hpp"
#include "inputs/source.hpp"
#include "inputs/source_drivers.hpp"
#include "optics/profile.hpp"
#include "player/player.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf::test {

inline Profile small_profile(const TempDir& dir) { return load_profile(write_small_profile(dir).string()); }

// 2 s (or `seconds`) at 30 fps, side by side: left view red-ish, right view blue-ish, each with a
// white box that moves 5 px per frame (the frame number, visible).
inline std::filesystem::path make_clip(const TempDir& dir, int seconds = 2) {
  return make_moving_box_clip(dir / "clip.mp4", seconds, 30, false);
}

struct Mean {
  double r = 0, g = 0, b = 0, max = 0;
};
inline Mean mean_of(const Image& image) {
  Mean m;
  const std::size_t n = static_cast<std::size_t>(image.width()) * image.height();
  for (std::size_t i = 0; i < n; ++i) {
    m.r += image.data()[i * 4];
    m.g += image.data()[i * 4 + 1];
    m.b += image.data()[i * 4 + 2];
    for (int c = 0; c < 3; ++c) m.max = std::max(m.max, static_cast<double>(image.data()[i * 4 + c]));
  }
  m.r /= n;
  m.g /= n;
  m.b /= n;
  return m;
}

// Pixels of the calibration grid's yellow centre cross and its lines (neither view has yellow).
inline int grid_pixels(const Image& image) {
  int n = 0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(image.width()) * image.height(); ++i) {
    const float* q = image.data() + i * 4;
    if (q[0] > 0.5f && q[1] > 0.5f && q[2] < 0.35f) ++n;
  }
  return n;
}

// The small test panel on the HMZ-T1's signal, without sound or messages.
inline PlayerOptions silent_options(const TempDir& dir) {
  PlayerOptions options;
  options.profile = small_profile(dir);
  options.signal = *find_signal("hdmi-fp-720p60");
  options.audio = false;
  options.quiet = true;
  return options;
}

// What a display is opened with to show the packed frame of `options`' 160x90 panel.
inline DisplayOptions small_panel_display_options(const PlayerOptions& options) {
  DisplayOptions display_options;
  display_options.signal = options.signal;
  display_options.packed = {options.signal.packed_width(160), options.signal.packed_height(90)};
  return display_options;
}

// The clip (or photo) at `path`, opened as `nelf play` opens its input.
inline std::unique_ptr<Source> open_input(const std::filesystem::path& path) {
  return open_source(SourceRequest{path.string(), "", std::nullopt, false, std::nullopt, true, false});
}

}  // namespace nelf::test
