#pragma once
// The stereo layout detection chain of DESIGN.md §6, as a pure function of the evidence:
// explicit flag → container/stream/frame stereo metadata → exact HDMI frame-packed frame size →
// filename tokens → aspect → mono (with a warning). The result names the rule that decided, which
// `nelf probe` reports.
#include <optional>
#include <string>
#include <string_view>

#include "inputs/stereo_metadata.hpp"

namespace nelf {

enum class LayoutRule { flag, metadata, frame_size, filename, aspect, fallback };
// "flag", "metadata", "frame-size", "filename", "aspect", "default".
std::string_view to_string(LayoutRule rule);

struct LayoutEvidence {
  std::optional<std::string> flag_layout;  // --layout
  bool flag_swap_eyes = false;             // --swap-eyes: swaps whatever was detected
  std::optional<StereoMetadata> metadata;  // stream side data, else a remembered frame-packing SEI
  int width = 0;                           // frame size as delivered (after rotation)
  int height = 0;
  double display_aspect = 0.0;  // width × SAR / height
  std::string path;             // for filename tokens
};

struct LayoutDecision {
  std::string layout;
  bool swap_eyes = false;
  LayoutRule rule = LayoutRule::fallback;
  std::string warning;  // non-empty when the user should know (the 2D fallback)
};

// Throws UnsupportedStereoMetadata when the metadata decides on a packing nelf cannot split.
LayoutDecision decide_layout(const LayoutEvidence& evidence);

// The two HDMI 1.4a frame-packed sizes (DESIGN.md §7); no other content has them.
bool is_hdmi_frame_packed_size(int width, int height);

}  // namespace nelf
