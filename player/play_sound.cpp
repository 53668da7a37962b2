#include "player/play_sound.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <utility>

#include "core/language_tags.hpp"
#include "core/user_error.hpp"

namespace nelf::playback {

namespace {

std::string track_list(const std::vector<AudioTrack>& tracks) {
  if (tracks.empty()) return "the input has no audio tracks to choose from";
  std::string list = "the input has ";
  for (std::size_t i = 0; i < tracks.size(); ++i)
    list += fmt::format("{}track {}", i == 0 ? "" : "; ", describe_audio_track(tracks[i]));
  return list;
}

std::string channel_words(int channels) {
  switch (channels) {
    case 1:
      return "mono";
    case 2:
      return "stereo";
    case 6:
      return "5.1";
    case 8:
      return "7.1";
    default:
      return fmt::format("{} channels", channels);
  }
}

}  // namespace

std::string describe_audio_track(const AudioTrack& track) {
  return fmt::format("{}: {}, {}, {} channels{}", track.number, track.language.empty() ? "no language" : track.language,
                     track.codec, track.channels, track.is_default ? " (default)" : "");
}

int choose_audio_track(const std::vector<AudioTrack>& tracks, std::optional<int> number,
                       const std::vector<std::string>& languages) {
  if (number) {
    if (*number < 1 || *number > static_cast<int>(tracks.size()))
      throw UserError(fmt::format("no audio track {} (--aid): {}", *number, track_list(tracks)), 2);
    return *number;
  }
  if (languages.empty()) return 0;
  for (const std::string& language : languages)
    for (const AudioTrack& track : tracks)
      if (same_language_tag(track.language, language)) return track.number;
  std::string asked;
  for (const std::string& language : languages) asked += (asked.empty() ? "" : ",") + language;
  throw UserError(fmt::format("no audio track in {} (--alang): {}", asked, track_list(tracks)), 2);
}

PlaySound::PlaySound(Source& source, const PlayerOptions& options)
    : source_(source), volume_(options.volume), muted_(options.mute) {
  if (!options.audio) {
    description_ = options.no_audio_reason;
    return;
  }
  tracks_ = source.audio_tracks();
  track_ = choose_audio_track(tracks_, options.audio_track, options.audio_languages);
  // As many channels as the track has (the device may refuse them: then stereo).
  int wanted_channels = 2;
  for (const AudioTrack& t : tracks_)
    if (track_ == 0 ? t.is_default : t.number == track_)
      wanted_channels = t.channels > 0 ? std::clamp(t.channels, 1, 8) : 2;
  OpenedAudio opened = source.open_audio({options.audio_rate, wanted_channels, track_});
  if (!opened.stream) {
    description_ = opened.why_not;
    return;
  }
  std::string why_not;
  audio_ = AudioOutput::open(opened.stream->sample_rate(), wanted_channels, why_not);
  if (!audio_) {
    description_ = fmt::format("no audio device ({})", why_not);
    return;
  }
  if (audio_->channels() != wanted_channels && !options.quiet)
    fmt::print(stderr, "nelf: the audio device does not take {}: the sound is mixed down to {}\n",
               channel_words(wanted_channels), channel_words(audio_->channels()));
  // The device may run at another rate or channel count: decode for what it has.
  if (audio_->sample_rate() != opened.stream->sample_rate() || audio_->channels() != opened.stream->channels()) {
    opened = source.open_audio({audio_->sample_rate(), audio_->channels(), track_});
    if (!opened.stream) {
      audio_.reset();
      description_ = opened.why_not;
      return;
    }
  }
  audio_->set_volume(volume_, muted_);
  description_ = audio_->description();
  if (!tracks_.empty()) {
    for (const AudioTrack& t : tracks_)
      if (track_ == 0 ? t.is_default : t.number == track_) {
        track_ = t.number;
        description_ += fmt::format(", audio track {}", describe_audio_track(t));
      }
  }
  feeder_ = std::make_unique<AudioFeeder>(std::move(opened.stream), *audio_);
}

std::string PlaySound::next_track(bool& changed) {
  changed = false;
  if (!audio_) return fmt::format("Audio: none ({})", description_);
  if (tracks_.size() < 2) return "Audio: the only track";
  return set_track(track_ % static_cast<int>(tracks_.size()) + 1, changed);
}

std::string PlaySound::set_track(int next, bool& changed) {
  changed = false;
  if (!audio_) return fmt::format("Audio: none ({})", description_);
  if (next < 1 || next > static_cast<int>(tracks_.size()))
    return fmt::format("Audio: no track {} (there are {})", next, tracks_.size());
  if (next == track_) return fmt::format("Audio: track {} already plays", next);
  OpenedAudio opened = source_.open_audio({audio_->sample_rate(), audio_->channels(), next});
  if (!opened.stream) return fmt::format("Audio: track {} cannot be played ({})", next, opened.why_not);
  feeder_.reset();  // before the new one feeds the same device
  feeder_ = std::make_unique<AudioFeeder>(std::move(opened.stream), *audio_);
  track_ = next;
  changed = true;
  const AudioTrack& t = tracks_[static_cast<std::size_t>(next - 1)];
  return fmt::format("Audio: track {}/{} ({}, {}, {})", t.number, tracks_.size(),
                     t.language.empty() ? "no language" : t.language, t.codec, channel_words(t.channels));
}

std::string PlaySound::volume_words() const {
  std::string words = fmt::format("Volume: {:.0f} %", volume_);
  if (muted_) words += " (muted)";
  if (!audio_) words += " (no sound)";
  return words;
}

std::string PlaySound::change_volume(double delta) {
  volume_ = std::clamp(volume_ + delta, 0.0, 130.0);
  if (audio_) audio_->set_volume(volume_, muted_);
  return volume_words();
}

std::string PlaySound::toggle_mute() {
  muted_ = !muted_;
  if (audio_) audio_->set_volume(volume_, muted_);
  return volume_words();
}

}  // namespace nelf::playback
