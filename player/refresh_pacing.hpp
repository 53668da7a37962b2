#pragma once
// The play loop's sense of time per refresh: how long a render takes, and (without vsync) the tick
// it sleeps to.
#include <algorithm>
#include <chrono>
#include <deque>
#include <thread>
#include <vector>

namespace nelf::playback {

// Time from the decision to the end of present(): the median of the last nine renders, so one slow
// frame on a loaded machine does not make the next ones come early.
class RenderTime {
 public:
  explicit RenderTime(double initial_s) : median_s_(initial_s) {}
  void add(double seconds) {
    recent_.push_back(seconds);
    if (recent_.size() > 9) recent_.pop_front();
    std::vector<double> sorted(recent_.begin(), recent_.end());
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    median_s_ = sorted[sorted.size() / 2];
  }
  double median_s() const { return median_s_; }

 private:
  std::deque<double> recent_;
  double median_s_;
};

// Without vsync nothing paces the loop but this: a tick every refresh period, slept to. The ticks
// keep their phase, as a display's refreshes do, so that a live source can be told them before the
// loop reaches them (a quad-buffer game times its swaps to them).
class RefreshTicker {
 public:
  using Steady = std::chrono::steady_clock;
  explicit RefreshTicker(double period_s)
      : period_(std::max(Steady::duration(1),
                         std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(period_s)))) {}
  void sleep_to_next() {
    next_ += period_;
    const auto now = Steady::now();
    // Far behind (a stall): on to the latest tick that has passed, whole periods on, rather than
    // racing through the ones missed.
    if (next_ < now - std::chrono::milliseconds(100)) next_ += (now - next_) / period_ * period_;
    std::this_thread::sleep_until(next_);
  }
  // The refresh sleep_to_next() slept to (it returns late when the loop overran it).
  Steady::time_point tick() const { return next_; }
  // The first tick at or after `t`.
  Steady::time_point next_after(Steady::time_point t) const {
    return t <= next_ ? next_ : next_ + (t - next_ + period_ - Steady::duration(1)) / period_ * period_;
  }

 private:
  Steady::duration period_;
  Steady::time_point next_ = Steady::now();
};

}  // namespace nelf::playback
