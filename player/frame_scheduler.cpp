#include "player/frame_scheduler.hpp"

#include <stdexcept>

namespace nelf {

namespace {
// Timestamps and clocks are doubles computed different ways (pts × time base, sample counts / rate):
// a frame exactly on the half-refresh boundary must not flip between due and not due because of
// rounding, so ties are decided with this tolerance, always in favour of "due".
constexpr double kTieTolerance_s = 1e-6;
}  // namespace

FrameScheduler::FrameScheduler(double refresh_period_s, double frame_period_s)
    : refresh_period_(refresh_period_s), nominal_frame_period_(frame_period_s) {
  if (!(refresh_period_s > 0.0)) throw std::invalid_argument("FrameScheduler: the refresh period must be > 0");
  if (frame_period_s < 0.0) throw std::invalid_argument("FrameScheduler: the frame period must be >= 0");
}

double FrameScheduler::frame_period() const {
  return nominal_frame_period_ > 0.0 ? nominal_frame_period_ : estimated_frame_period_;
}

bool FrameScheduler::is_due(double pts, double visible_at) const {
  return pts <= visible_at + 0.5 * refresh_period_ + kTieTolerance_s;
}

void FrameScheduler::reset() {
  on_screen_pts_.reset();
  estimated_frame_period_ = 0.0;
}

std::size_t FrameScheduler::stale(double visible_at, std::span<const double> queued) const {
  std::size_t due = 0;
  while (due < queued.size() && is_due(queued[due], visible_at)) ++due;
  return due > 0 ? due - 1 : 0;
}

FrameDecision FrameScheduler::decide(double visible_at, std::span<const double> queued, bool end_of_stream) {
  FrameDecision decision;
  std::size_t due = 0;  // frames at the front of the queue that are due now
  while (due < queued.size() && is_due(queued[due], visible_at)) ++due;

  if (due > 0) {
    decision.drop = due - 1;
    decision.show_front = true;
    const double pts = queued[due - 1];
    if (on_screen_pts_ && pts > *on_screen_pts_) {
      // Estimate from consecutive decoded frames: the gap to the newest shown frame spans the
      // dropped ones too.
      estimated_frame_period_ = (pts - *on_screen_pts_) / static_cast<double>(due);
    }
    on_screen_pts_ = pts;
    counters_.dropped += static_cast<std::int64_t>(decision.drop);
    ++counters_.shown;
  } else if (on_screen_pts_) {
    const double period = frame_period();
    const bool successor_due = period > 0.0 && is_due(*on_screen_pts_ + period, visible_at);
    if (queued.empty() && end_of_stream) {
      // The last frame stays for its own period, then playback is over.
      decision.finished = period <= 0.0 || successor_due;
    } else if (queued.empty() && successor_due) {
      decision.repeat = true;
      ++counters_.repeated;
    }
  } else if (queued.empty() && end_of_stream) {
    decision.finished = true;  // nothing was ever shown and nothing will come
  }
  decision.shown_pts = on_screen_pts_;
  return decision;
}

}  // namespace nelf
