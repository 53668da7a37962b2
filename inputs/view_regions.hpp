#pragma once
// Where the two views of a stereo layout lie in a full frame, and at what aspect they are displayed.
// Shared by still images (split_frame copies the regions into Images) and video (the regions of
// each decoded frame are copied into the two textures the compositor samples).
#include "inputs/stereo_layout.hpp"

namespace nelf {

struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
};

struct ViewRegions {
  PixelRect left, right;
  double display_aspect = 0.0;  // of each view
};

// `frame_display_aspect` is the whole frame's display aspect (width × pixel aspect / height);
// 0 means square pixels. Half layouts are anamorphic: each view is shown at the frame's aspect.
// Throws LayoutError when the layout does not fit the frame or needs two frames (alt, pair).
ViewRegions view_regions(StereoLayout layout, int width, int height, bool swap_eyes, double frame_display_aspect = 0.0);

}  // namespace nelf
