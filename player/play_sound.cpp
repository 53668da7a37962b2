#include "player/play_sound.hpp"

#include <fmt/format.h>

#include <optional>

#include "inputs/audio_source.hpp"

namespace nelf::playback {

PlaySound::PlaySound(Source& source, const PlayerOptions& options) {
  if (!options.audio) {
    description_ = "--no-audio";
    return;
  }
  if (source.has_generated_audio()) {
    description_ = "the synthetic clip's tone is not played";
    return;
  }
  if (source.audio_path().empty()) {
    description_ = "no audio stream";
    return;
  }
  std::optional<AudioSource> audio_source;
  try {
    audio_source.emplace(source.audio_path(),
                         AudioSourceOptions{options.audio_rate, source.origin_s(), options.allow_network});
  } catch (const AudioError& e) {
    description_ = std::string(e.what()).find("no audio stream") != std::string::npos
                       ? "no audio stream"
                       : fmt::format("the audio cannot be decoded ({})", e.what());
    return;
  }
  std::string why_not;
  audio_ = AudioOutput::open(audio_source->sample_rate(), why_not);
  if (!audio_) {
    description_ = fmt::format("no audio device ({})", why_not);
    return;
  }
  // The device may run at another rate: decode for the rate it has.
  if (audio_->sample_rate() != audio_source->sample_rate())
    audio_source.emplace(source.audio_path(),
                         AudioSourceOptions{audio_->sample_rate(), source.origin_s(), options.allow_network});
  description_ = audio_->description();
  feeder_ = std::make_unique<AudioFeeder>(std::move(*audio_source), *audio_);
}

}  // namespace nelf::playback
