#pragma once
#include <memory>
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

// The maps a depth source hands out with its frames, written again once no frame holds them: a
// fresh pair of full-size float maps costs more in zero-filling and page faults than the work that
// fills them. A few are kept (the frames queued between a source and the compositor); when all are
// held, a new pair is made and not kept. For one source, used from its thread.
class ReusableDisparityMaps {
 public:
  std::shared_ptr<StereoDisparity> next() {
    for (std::shared_ptr<StereoDisparity>& maps : handed_out_)
      if (maps.use_count() == 1) return maps;  // only this pool holds it: no frame can any more
    auto maps = std::make_shared<StereoDisparity>();
    if (handed_out_.size() < kKept) handed_out_.push_back(maps);
    return maps;
  }

 private:
  static constexpr std::size_t kKept = 4;
  std::vector<std::shared_ptr<StereoDisparity>> handed_out_;
};

}  // namespace nelf
