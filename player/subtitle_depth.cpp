#include "player/subtitle_depth.hpp"

#include <algorithm>

#include "inputs/stereo_matcher.hpp"

namespace nelf {
namespace {

// How long an estimate of the views stands for the frames after it: matching a 1080p pair takes
// ~25 ms of both cores, too much for every frame of a movie, and the content beneath a line rarely
// moves in depth faster than this.
constexpr double kEstimateLifetimeS = 0.25;
// A jump in the frame times longer than this (or back) is a seek: what was beneath the line is gone.
constexpr double kSeekGapS = 1.0;

StereoMatcherSettings one_frame_matching() {
  StereoMatcherSettings settings;
  settings.temporal_weight = 0.0;  // estimates are frames apart: nothing to temper one with
  return settings;
}

}  // namespace

SubtitleDepthFollower::SubtitleDepthFollower() : matcher_(std::make_unique<StereoMatcher>(one_frame_matching())) {}
SubtitleDepthFollower::~SubtitleDepthFollower() = default;

void SubtitleDepthFollower::reset() {
  line_box_.reset();
  line_measured_ = false;
  last_pts_.reset();
  estimate_.reset();
}

double SubtitleDepthFollower::parallax(const StereoVideoFrame& frame, const SubtitleBitmap& subtitle,
                                       const SubtitleDepth& depth) {
  const auto limited = [](double percent) {
    return std::clamp(percent, -max_sub_parallax_percent, max_sub_parallax_percent);
  };
  if (!depth.follows_content) return limited(depth.percent);
  // A new line after the seek starts where the last one was (line_content_ is kept).
  if (last_pts_ && (frame.pts_s < *last_pts_ || frame.pts_s - *last_pts_ > kSeekGapS)) reset();
  last_pts_ = frame.pts_s;
  const std::optional<SubtitleBox> box = subtitle_box(subtitle);
  if (!box) {
    line_box_.reset();
    return limited(line_content_ + depth.percent);
  }
  const bool new_line = !line_box_ || *box != *line_box_;
  if (new_line) {
    line_box_ = box;
    line_measured_ = false;
  }

  std::shared_ptr<const StereoDisparity> disparity = frame.disparity;
  if (!disparity) {
    if (!estimate_ || frame.pts_s - estimate_pts_ >= kEstimateLifetimeS) {
      estimate_ = matcher_->estimate(frame);
      estimate_pts_ = frame.pts_s;
    }
    disparity = estimate_;
  }
  const auto [width, height] = subtitle_canvas(frame);
  const std::optional<double> beneath =
      disparity ? content_parallax_beneath(*disparity, *box, width, height) : std::nullopt;
  if (beneath) {
    // A new line takes the content's depth; the line being read only comes nearer.
    line_content_ = line_measured_ ? std::max(line_content_, *beneath) : *beneath;
    line_measured_ = true;
  }
  // Unmeasured (a flat or black picture beneath): where the last line was.
  return limited(line_content_ + depth.percent);
}

}  // namespace nelf
