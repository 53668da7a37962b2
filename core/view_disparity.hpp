#pragma once
#include <vector>

namespace nelf {

// The content's depth per view pixel, as the horizontal disparity to the other view: the form
// every depth source can give (a stereo matcher measures it, a synthetic scene or a game's depth
// buffer converts to it) and the compositor turns into distance with the profile's screen geometry.
struct ViewDisparity {
  int width = 0, height = 0;  // the view's pixels (may be coarser than the frame's; scaled by the user)
  // Row-major, in pixels of this map. The same scene point is at x - d in the right view for a
  // pixel x of the left view, and at x + d in the left view for a pixel x of the right view, so
  // d > 0 is in front of the emulated screen, 0 on it, < 0 behind. NaN: unknown (occluded, unmatched).
  std::vector<float> d;
};

// Where a frame's disparity came from: the source knew it exactly (a synthetic scene), a game's
// depth buffers gave it, or it was estimated from the two views.
enum class DisparityOrigin { known, game, estimated };

struct StereoDisparity {
  ViewDisparity left, right;
  DisparityOrigin origin = DisparityOrigin::estimated;
};

}  // namespace nelf
