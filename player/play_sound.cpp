#include "player/play_sound.hpp"

#include <fmt/format.h>

#include <utility>

namespace nelf::playback {

PlaySound::PlaySound(Source& source, const PlayerOptions& options) {
  if (!options.audio) {
    description_ = "--no-audio";
    return;
  }
  OpenedAudio opened = source.open_audio({options.audio_rate, 2});
  if (!opened.stream) {
    description_ = opened.why_not;
    return;
  }
  std::string why_not;
  audio_ = AudioOutput::open(opened.stream->sample_rate(), why_not);
  if (!audio_) {
    description_ = fmt::format("no audio device ({})", why_not);
    return;
  }
  // The device may run at another rate: decode for the rate it has.
  if (audio_->sample_rate() != opened.stream->sample_rate()) {
    opened = source.open_audio({audio_->sample_rate(), 2});
    if (!opened.stream) {
      audio_.reset();
      description_ = opened.why_not;
      return;
    }
  }
  description_ = audio_->description();
  feeder_ = std::make_unique<AudioFeeder>(std::move(opened.stream), *audio_);
}

}  // namespace nelf::playback
