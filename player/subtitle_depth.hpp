#pragma once
// --sub-parallax auto: each subtitle just in front of the content beneath it (issue #15's
// consumers). The content's depth is the frame's own when it carries one (a synthetic scene's, or
// --depth's estimate), otherwise estimated from the two views when a subtitle needs it. A line keeps
// its depth while it is read: it comes nearer when the content beneath it does (never behind the
// picture), but does not wander back until the next line.
#include <memory>
#include <optional>

#include "compositor/overlays/subtitle_overlay.hpp"
#include "core/frames.hpp"
#include "core/subtitle_bitmap.hpp"

namespace nelf {

class StereoMatcher;

// The depth a subtitle is drawn at: a fixed parallax (--sub-parallax P), or, following the content,
// `percent` in front of it (auto; the keys move that margin).
struct SubtitleDepth {
  bool follows_content = false;
  double percent = 0.0;
};

// What `--sub-parallax auto` starts with: a quarter of a percent of the view width in front of the
// content, the step of the subtitle depth keys: near enough to read with the picture, far enough
// in front not to be taken for part of it.
constexpr double auto_sub_margin_percent = 0.25;

// One stream's follower, used by the thread that draws its subtitles (it keeps the line being read
// and a matcher); it tells a seek by the frame times going back or jumping.
class SubtitleDepthFollower {
 public:
  SubtitleDepthFollower();
  ~SubtitleDepthFollower();
  SubtitleDepthFollower(const SubtitleDepthFollower&) = delete;
  SubtitleDepthFollower& operator=(const SubtitleDepthFollower&) = delete;

  // The parallax (percent of the view width, within ±max_sub_parallax_percent) to draw `subtitle`
  // over `frame` at: `depth.percent` itself when fixed, that much in front of the content beneath
  // when following it. Call before the subtitle is drawn into the frame's views.
  double parallax(const StereoVideoFrame& frame, const SubtitleBitmap& subtitle, const SubtitleDepth& depth);

 private:
  // Forgets the line being read and the last estimate; the depth of the last line stays.
  void reset();
  std::unique_ptr<StereoMatcher> matcher_;
  std::optional<SubtitleBox> line_box_;  // the line being read (its box tells one line from the next)
  double line_content_ = 0.0;            // the nearest content beneath it so far, percent
  bool line_measured_ = false;
  std::optional<double> last_pts_;
  std::shared_ptr<const StereoDisparity> estimate_;  // the last estimate, and the frame time of it
  double estimate_pts_ = 0.0;
};

}  // namespace nelf
