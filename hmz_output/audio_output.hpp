#pragma once
// Sound for `nelf play` through SDL2 audio, and the clock playback follows (DESIGN.md §7).
//
// With sound, the AUDIO CLOCK is master: the presentation time of the sample being heard now =
// the pts just past the last sample handed to SDL, minus what SDL still holds in its queue, minus
// the device buffer (SDL pulls whole buffers; between pulls the clock is interpolated with the
// system clock, at most one buffer ahead, so that it advances smoothly instead of in 10 ms steps).
// Without sound (no audio device, no audio stream, --no-audio) a monotonic SystemClock is master.
#include <SDL2/SDL.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>

#include "core/frames.hpp"

namespace nelf {

// The master clock of playback, in seconds on the pts timeline. Thread-safe.
class PlaybackClock {
 public:
  virtual ~PlaybackClock() = default;
  virtual double now() const = 0;
  virtual void set_paused(bool paused) = 0;
  virtual bool paused() const = 0;
  // After a seek: the clock continues from `seconds` (audio: once the new samples play).
  virtual void restart_at(double seconds) = 0;
};

// Monotonic system time, pausable, starting at 0 (or where restart_at puts it).
class SystemClock final : public PlaybackClock {
 public:
  using Clock = std::chrono::steady_clock;
  SystemClock();
  double now() const override;
  void set_paused(bool paused) override;
  bool paused() const override;
  void restart_at(double seconds) override;

 private:
  double now_locked() const;
  mutable std::mutex mutex_;
  Clock::time_point origin_;  // system time at which the clock read base_
  double base_ = 0.0;
  bool paused_ = false;
};

// Scales `samples` by the gain of `volume` (mpv's scale: 0 to 130, 100 = as decoded, cubic, so that
// equal steps sound like equal steps), or silences them when `muted`.
void apply_volume(std::span<float> samples, double volume, bool muted);

// An open SDL audio device playing interleaved float samples (stereo, or up to 7.1 in SDL2's
// channel order). Starts paused until the first set_paused(false).
class AudioOutput final : public PlaybackClock {
 public:
  // Opens the default output device (SDL_AUDIODRIVER picks the driver) at `sample_rate` with
  // `channels` (1 to 8) when the device takes that many, else stereo (channels() says which), or
  // says why not in `why_not` and returns null: no audio subsystem, no device.
  static std::unique_ptr<AudioOutput> open(int sample_rate, int channels, std::string& why_not);
  static std::unique_ptr<AudioOutput> open(int sample_rate, std::string& why_not) {
    return open(sample_rate, 2, why_not);
  }
  ~AudioOutput() override;
  AudioOutput(const AudioOutput&) = delete;
  AudioOutput& operator=(const AudioOutput&) = delete;

  int sample_rate() const { return spec_.freq; }
  int channels() const { return spec_.channels; }
  // "pulseaudio, 48000 Hz, 2 channels, 512-sample buffer"
  std::string description() const;

  // Appends samples (chunks of channels() channels), scaled by the volume. A chunk starting later
  // than the end of what was queued is preceded by silence (so that the clock stays on the pts
  // timeline); one starting earlier is queued as it is.
  void queue(const AudioChunk& chunk);
  // The volume (0 to 130, see apply_volume) and mute of the chunks queued from now on: what is
  // already queued (the feeder keeps about half a second) plays out at the old volume.
  void set_volume(double volume, bool muted);
  // Seconds of sound queued and not yet heard.
  double buffered_s() const;
  // No more samples will come: once the queue runs dry the clock goes on with the system clock
  // instead of stopping (video longer than audio).
  void end_of_stream();

  double now() const override;
  void set_paused(bool paused) override;
  bool paused() const override;
  // Drops everything queued (a seek); the clock holds at `seconds` until new samples play.
  void restart_at(double seconds) override;

 private:
  AudioOutput(SDL_AudioDeviceID device, const SDL_AudioSpec& spec);
  double now_locked() const;

  SDL_AudioDeviceID device_;
  SDL_AudioSpec spec_;
  mutable std::mutex mutex_;
  std::optional<double> queued_end_pts_;  // pts just past the last queued sample
  double hold_pts_ = 0.0;                 // the clock before any sample was queued
  bool paused_ = true;
  bool end_of_stream_ = false;
  double volume_ = 100.0;
  bool muted_ = false;
  // Smoothing: the last computed clock, when it changed, and what the queue held then.
  mutable std::uint32_t last_queued_bytes_ = 0;
  mutable double last_clock_ = 0.0;
  mutable std::chrono::steady_clock::time_point last_change_{};
  mutable std::optional<std::chrono::steady_clock::time_point> drained_at_;
  mutable double drained_base_ = 0.0;
};

}  // namespace nelf
