#pragma once
// Frame pacing for live playback: at each display refresh, which decoded frame to show so that
// video follows the master clock (the audio clock, or a monotonic clock without audio). Pure: it
// sees only times and timestamps, so every cadence and failure can be unit-tested without a
// display.
//
// A frame is due at the refresh whose visible time is nearest its pts: pts ≤ visible_at + half a
// refresh period. Each refresh shows the newest due frame; older due frames that were never shown
// are dropped (their time passed while a newer one was already due). When no new frame is due the
// one on screen stays: that is natural cadence (24 fps on 60 Hz shows frames for 3, 2, 3, 2 …
// refreshes) unless the next frame should be there by now, i.e. its expected pts (last shown pts +
// frame period) is due but it has not been decoded yet: then the refresh is a repeat.
// Frames are therefore never shown more than half a refresh early, and a frame stays on screen at
// most one frame period past its successor's pts unless decoding is late (counted as repeats).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace nelf {

struct FrameDecision {
  std::size_t drop = 0;             // discard this many frames from the front of the queue, unshown
  bool show_front = false;          // then show (and remove) the new front of the queue
  bool repeat = false;              // the frame that is due is not decoded yet: the old one stays
  bool finished = false;            // end of stream and the last frame has had its time on screen
  std::optional<double> shown_pts;  // pts of the frame on screen after this refresh, if any
};

struct FrameCounters {
  std::int64_t shown = 0;     // distinct frames displayed
  std::int64_t repeated = 0;  // refreshes that kept an older frame because the due one was late
  std::int64_t dropped = 0;   // frames discarded without ever being shown
};

class FrameScheduler {
 public:
  // refresh_period_s: the display's refresh period (> 0). frame_period_s: the source's nominal
  // frame period; 0 = estimate it from the timestamps shown.
  FrameScheduler(double refresh_period_s, double frame_period_s);

  // visible_at: master clock time at which this refresh becomes visible. queued: pts of the frames
  // decoded and not yet shown, oldest first (ascending). end_of_stream: no more frames will come.
  FrameDecision decide(double visible_at, std::span<const double> queued, bool end_of_stream);
  // How many frames at the front of `queued` a refresh visible at `visible_at` would drop unshown
  // (the due ones but the newest); changes nothing. The player composites ahead only the frames
  // after them.
  std::size_t stale(double visible_at, std::span<const double> queued) const;

  // After a seek or a flush: nothing is on screen any more as far as pacing is concerned (the
  // counters are kept).
  void reset();

  const FrameCounters& counters() const { return counters_; }
  double refresh_period() const { return refresh_period_; }
  // The frame period in use (the nominal one, or the estimate; 0 before there is one).
  double frame_period() const;

 private:
  bool is_due(double pts, double visible_at) const;

  double refresh_period_;
  double nominal_frame_period_;
  double estimated_frame_period_ = 0.0;
  std::optional<double> on_screen_pts_;
  FrameCounters counters_;
};

}  // namespace nelf
