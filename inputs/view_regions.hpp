#pragma once
// Where the two views of a stereo layout lie in a full frame, and at what aspect they are displayed.
// Shared by still images (split_frame copies the regions into Images) and video (the regions of
// each decoded frame are copied into the two textures the compositor samples).
#include <optional>
#include <string>

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

// A live picture's views (a captured window, a game's picture at its swaps): its layout detected
// from its size or given (`layout`, --swap-eyes), and where the views lie in it; the detection's
// warning is said on stderr unless `quiet`. Throws UserError (status 2) naming `input` when the
// layout does not fit the picture.
struct LivePictureViews {
  LayoutDecision decision;
  ViewRegions regions;
};
LivePictureViews live_picture_views(const std::string& input, std::optional<StereoLayout> layout, bool swap_eyes,
                                    int width, int height, bool quiet);

}  // namespace nelf
