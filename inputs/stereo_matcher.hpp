#pragma once
// The content's depth estimated from the two views of a stereo frame (issue #15, the `estimated`
// depth source): block matching at a reduced working resolution in both directions, a
// left-right consistency check that leaves occluded and unmatched pixels unknown (NaN), an
// edge-aware upsampling guided by the view, and, on video, each frame's estimate tempered by the
// previous one where the views did not change. OpenCV does the matching; its headers stay in
// stereo_matcher.cpp (nelf_inputs links it PRIVATE).
#include <memory>

#include "core/frames.hpp"
#include "core/view_disparity.hpp"

namespace nelf {

struct StereoMatcherSettings {
  // The working resolution is the largest width of at most `max_working_width` (and at least
  // `min_working_width`) at which matching the frame's disparity range costs at most
  // `cost_budget` pixel × disparity candidates a view: a wide range (a plane close to the eye)
  // is matched coarser rather than slower.
  int max_working_width = 480;
  int min_working_width = 192;
  double cost_budget = 6.5e6;
  // The maps come back at up to this many times the working resolution (edge-aware upsampled).
  int output_scale = 2;
  // Below this share of matched pixels the frame has no usable depth (flat, black, no texture):
  // `estimate` gives none rather than a guess.
  double min_matched_share = 0.05;
  // How much of the previous frame's estimate a pixel whose view did not change keeps (0: none).
  double temporal_weight = 0.5;
  // OpenCV's worker threads for the matching (0: one per core).
  int threads = 0;
};

// One stream's estimator: keeps the previous frame's views and maps for the temporal filter, so
// one instance per stream, used from one thread at a time; `reset` after a seek or a cut.
class StereoMatcher {
 public:
  explicit StereoMatcher(StereoMatcherSettings settings = {});
  ~StereoMatcher();
  StereoMatcher(const StereoMatcher&) = delete;
  StereoMatcher& operator=(const StereoMatcher&) = delete;

  // Both views' disparity maps (DisparityOrigin::estimated) for the views of `frame` (RGBA8 or
  // RGBA16, whole views or block means), in the maps' own pixels; null when the frame has too
  // little texture to match (the caller falls back to the flat screen).
  std::shared_ptr<const StereoDisparity> estimate(const StereoVideoFrame& frame);
  void reset();

 private:
  struct State;
  StereoMatcherSettings settings_;
  std::unique_ptr<State> state_;
};

// Both views' disparity of a still (16-bit views, so its precision is kept), as `estimate` gives a
// frame's but without the cost budget (matched at max_working_width whatever the range); null when
// the views differ in size or cannot be matched.
std::shared_ptr<const StereoDisparity> estimate_still_disparity(const StereoPair& views);

}  // namespace nelf
