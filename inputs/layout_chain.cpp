#include "inputs/layout_chain.hpp"

#include "inputs/layout_detection_hooks.hpp"

namespace nelf {

std::string_view to_string(LayoutRule rule) {
  switch (rule) {
    case LayoutRule::flag:
      return "flag";
    case LayoutRule::metadata:
      return "metadata";
    case LayoutRule::frame_size:
      return "frame-size";
    case LayoutRule::filename:
      return "filename";
    case LayoutRule::aspect:
      return "aspect";
    case LayoutRule::fallback:
      return "default";
  }
  return "default";
}

bool is_hdmi_frame_packed_size(int width, int height) {
  return (width == 1280 && height == 1470) || (width == 1920 && height == 2205);
}

LayoutDecision decide_layout(const LayoutEvidence& evidence) {
  const bool flip = evidence.flag_swap_eyes;
  if (evidence.flag_layout) return {*evidence.flag_layout, flip, LayoutRule::flag, {}};
  if (evidence.metadata) {
    const MetadataLayout from_metadata = layout_from_stereo_metadata(*evidence.metadata, evidence.display_aspect);
    return {from_metadata.layout, from_metadata.swap_eyes != flip, LayoutRule::metadata, {}};
  }
  if (is_hdmi_frame_packed_size(evidence.width, evidence.height)) return {"fp", flip, LayoutRule::frame_size, {}};
  if (auto hint = layout_hint_from_filename(evidence.path, evidence.display_aspect))
    return {hint->layout, hint->swap_eyes != flip, LayoutRule::filename, {}};
  if (auto hint = layout_hint_from_aspect(evidence.display_aspect))
    return {hint->layout, hint->swap_eyes != flip, LayoutRule::aspect, {}};
  return {"mono", flip, LayoutRule::fallback,
          "no stereo layout detected (no metadata, no telling file name or aspect); showing it as 2D; pass "
          "--layout to choose one"};
}

}  // namespace nelf
