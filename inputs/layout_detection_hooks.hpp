#pragma once
// The two heuristic steps of stereo layout detection (DESIGN.md §6) that do not depend on the
// media's metadata: filename tokens and frame aspect. They belong to inputs/stereo_layout (layout
// enum, view splitting, detection) developed on another branch; on integration these two functions
// forward to it (or are replaced by it) and decide_layout() in inputs/layout_chain.hpp keeps working.
#include <optional>
#include <string>
#include <string_view>

namespace nelf {

struct LayoutHint {
  std::string layout;  // a nelf layout name
  bool swap_eyes = false;
};

// Release-name tokens in the file name, any case: sbs/fsbs/full-sbs, hsbs/h-sbs/half-sbs,
// tab/ou/ftab/fou, htab/h-tab/hou/h-ou/half-ou, lr/rl (side by side, half or full from the aspect),
// and `3d` alone meaning half side-by-side. nullopt when no token matches.
std::optional<LayoutHint> layout_hint_from_filename(std::string_view path, double frame_display_aspect);

// W/H ≥ 3 is full side-by-side, W/H ≤ 1 full top-bottom; anything between says nothing.
std::optional<LayoutHint> layout_hint_from_aspect(double frame_display_aspect);

}  // namespace nelf
