#pragma once
// Output signals (DESIGN.md §7): how the two eye images are laid out in the frame that leaves nelf.
// The HDMI 1.4a frame-packed formats carry their video timing (for xrandr mode lines and KMS);
// the plain outputs (sbs, tab, left, right) are for files and previews and follow the panel's size.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/image.hpp"
#include "optics/profile.hpp"

namespace nelf {

// CEA-861 video timing of a frame-packed mode: the packed frame is the active area; the vertical
// blanking follows the second eye. Sync positions count from the start of the line / frame.
struct VideoTiming {
  int h_active, h_sync_start, h_sync_end, h_total;
  int v_active, v_sync_start, v_sync_end, v_total;
  double pixel_clock_mhz;
  bool h_sync_positive = true;
  bool v_sync_positive = true;
  double refresh_hz() const { return pixel_clock_mhz * 1e6 / (static_cast<double>(h_total) * v_total); }
};

enum class SignalKind {
  hdmi_frame_packing,  // left on top, black gap, right below
  side_by_side,        // left | right, full width each
  top_bottom,          // left over right, no gap
  single_eye,          // one eye only
};

struct Signal {
  std::string_view name;
  SignalKind kind;
  // Fixed eye area of the HDMI formats (0 for the plain outputs, whose eye size is the panel's).
  int eye_width = 0;
  int eye_height = 0;
  int gap_rows = 0;
  std::optional<VideoTiming> timing;
  Eye eye = Eye::left;  // the eye a single_eye signal shows

  // The packed frame for eye images of `eye_w` x `eye_h` pixels.
  int packed_width(int eye_w) const;
  int packed_height(int eye_h) const;
  // Row where the right eye starts in a frame-packed signal (eye_height + gap_rows).
  int right_eye_first_row() const { return eye_height + gap_rows; }
};

// hdmi-fp-720p60, hdmi-fp-720p50, hdmi-fp-1080p24, sbs, tab, left, right.
std::optional<Signal> find_signal(std::string_view name);
const std::vector<std::string_view>& signal_names();

}  // namespace nelf
