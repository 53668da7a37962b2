#pragma once
// The sound of `nelf play` and the master clock it gives: the source's audio (a file's track, the
// synthetic clip's tone) fed to the device in as many channels as the track has when the device
// takes them, at the volume asked for, whose clock then paces the pictures; else the system clock,
// with the reason in words.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hmz_output/audio_output.hpp"
#include "inputs/source.hpp"
#include "player/audio_feeder.hpp"
#include "player/player.hpp"

namespace nelf::playback {

// The audio track to play (AudioFormat::track): `number` when the input has that track, else the
// first track in the first of `languages` (ISO 639-2, as tagged: "eng", "ger"; any case) that one
// has, else 0 (the input's default). Throws UserError, one line naming the tracks there are, when
// the track or no language is there.
int choose_audio_track(const std::vector<AudioTrack>& tracks, std::optional<int> number,
                       const std::vector<std::string>& languages);

// "2: ger, ac3, 6 channels (default)"
std::string describe_audio_track(const AudioTrack& track);

class PlaySound {
 public:
  // Opens the source's audio (the track options choose) on the default device unless options.audio
  // is off or there is none to play; failures (no stream, undecodable, no device) become the reason,
  // never an error. Throws UserError when the track chosen is not there (choose_audio_track).
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
  // Plays the input's next audio track (after the last, the first) from where the caller seeks it
  // to next; says what plays now, or why nothing changed. True in `changed` when the track did.
  std::string next_track(bool& changed);
  // Plays track `number` (AudioTrack::number) instead, as next_track does.
  std::string set_track(int number, bool& changed);
  // The AudioTrack::number playing; 0 when there is no sound.
  int track() const { return audio_ ? track_ : 0; }
  int track_count() const { return static_cast<int>(tracks_.size()); }

  // The volume (0 to 130, 100 as decoded) by `delta`; what it is now, in words ("Volume: 54 %").
  std::string change_volume(double delta);
  std::string toggle_mute();
  double volume() const { return volume_; }
  bool muted() const { return muted_; }

  std::int64_t decode_errors() const { return feeder_ ? feeder_->decode_errors() : 0; }
  // Stops feeding (before the source goes).
  void stop() { feeder_.reset(); }

 private:
  std::string volume_words() const;

  Source& source_;
  SystemClock system_clock_;
  std::unique_ptr<AudioOutput> audio_;
  std::unique_ptr<AudioFeeder> feeder_;
  std::string description_;
  std::vector<AudioTrack> tracks_;
  int track_ = 0;  // the AudioTrack::number playing; 0: the input's default
  double volume_ = 100.0;
  bool muted_ = false;
};

}  // namespace nelf::playback
