#pragma once
// The sound of `nelf play` and the master clock it gives: the source's audio (a file's, the
// synthetic clip's tone) fed to the device, whose clock then paces the pictures; else the system
// clock, with the reason in words.
#include <memory>
#include <string>

#include "hmz_output/audio_output.hpp"
#include "inputs/source.hpp"
#include "player/audio_feeder.hpp"
#include "player/player.hpp"

namespace nelf::playback {

class PlaySound {
 public:
  // Opens the source's audio on the default device unless options.audio is off or there is none
  // to play; failures (no stream, undecodable, no device) become the reason, never an error.
  PlaySound(Source& source, const PlayerOptions& options);

  PlaybackClock& clock() { return audio_ ? static_cast<PlaybackClock&>(*audio_) : system_clock_; }
  bool playing() const { return audio_ != nullptr; }
  // "pulseaudio, 48000 Hz …", or why there is no sound ("--no-audio", "no audio stream", …).
  const std::string& description() const { return description_; }
  // The device's own clock, when there is sound (the frame log writes it beside the master clock).
  const AudioOutput* output() const { return audio_.get(); }

  // After a seek: the sound continues from `seconds` (nothing when there is none).
  void seek(double seconds) {
    if (feeder_) feeder_->seek(seconds);
  }
  std::int64_t decode_errors() const { return feeder_ ? feeder_->decode_errors() : 0; }
  // Stops feeding (before the source goes).
  void stop() { feeder_.reset(); }

 private:
  SystemClock system_clock_;
  std::unique_ptr<AudioOutput> audio_;
  std::unique_ptr<AudioFeeder> feeder_;
  std::string description_;
};

}  // namespace nelf::playback
