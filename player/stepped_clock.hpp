#pragma once
// A master clock that moves only when the play loop has finished a refresh, by one refresh period:
// what the player's tests inject (PlayerOptions::clock) so that every frame decision follows from
// the clip and the refresh rate alone, with no sleeps and whatever the machine's load.
#include <mutex>

#include "hmz_output/audio_output.hpp"

namespace nelf::playback {

class SteppedClock final : public PlaybackClock {
 public:
  double now() const override {
    std::lock_guard lock(mutex_);
    return now_;
  }
  void set_paused(bool paused) override {
    std::lock_guard lock(mutex_);
    paused_ = paused;
  }
  bool paused() const override {
    std::lock_guard lock(mutex_);
    return paused_;
  }
  void restart_at(double seconds) override {
    std::lock_guard lock(mutex_);
    now_ = seconds;
  }
  // `seconds` have passed (none while paused).
  void advance(double seconds) {
    std::lock_guard lock(mutex_);
    if (!paused_) now_ += seconds;
  }

 private:
  mutable std::mutex mutex_;
  double now_ = 0.0;
  bool paused_ = false;
};

}  // namespace nelf::playback
