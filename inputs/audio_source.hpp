#pragma once
// A media file's audio as an AudioStream: the default audio stream, decoded with libavcodec and
// (or the track asked for) resampled with libswresample to interleaved float (stereo unless asked otherwise) at the
// output's rate, each chunk stamped with its presentation time on the video's timeline (seconds
// from the same origin as StereoVideoFrame::pts_s). Damaged packets are skipped and counted, as
// for video.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/audio_stream.hpp"
#include "core/frames.hpp"

extern "C" {
#include <libavutil/channel_layout.h>
}

namespace nelf {

struct AudioSourceOptions {
  int sample_rate = 48000;     // of the delivered samples
  double origin_s = 0.0;       // container time that becomes pts 0 (the video's origin)
  bool allow_network = false;  // false: FFmpeg may only use the file and pipe protocols
  int channels = 2;            // of the delivered samples (1 to 8, in SDL2's channel order)
  int track = 0;               // the N-th audio stream of the file (AudioTrack::number); 0: FFmpeg's best
};

class AudioSource final : public AudioStream {
 public:
  // True when `path` has an audio stream FFmpeg can decode (false also when it cannot be opened).
  static bool has_audio(const std::string& path, bool allow_network = false);

  // Opens the default audio stream. Throws AudioError when there is none or it cannot be decoded.
  AudioSource(const std::string& path, AudioSourceOptions options = {});
  ~AudioSource() override;
  AudioSource(AudioSource&&) noexcept;
  AudioSource& operator=(AudioSource&&) noexcept;

  // The next chunk in order, or nullopt at the end of the stream.
  std::optional<AudioChunk> next() override;
  // The next chunks start at `seconds` (pts timeline); earlier samples of the first one are cut.
  void seek(double seconds) override;

  int sample_rate() const override;
  int channels() const override;
  std::string codec_name() const;
  std::string description() const override { return codec_name(); }
  std::int64_t decode_errors() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The channel layout of `channels` (1 to 8) interleaved in the order SDL2 plays them: stereo,
// 5.1 (FL FR FC LFE SL SR), 7.1 (FL FR FC LFE BL BR SL SR) … what the samples are converted to.
AVChannelLayout sdl_channel_layout(int channels);

// The audio tracks of the media file `path` (empty when it has none or cannot be opened).
std::vector<AudioTrack> file_audio_tracks(const std::string& path, bool allow_network);

// The audio of the media file `path` as `format` asks (0: 48000 Hz, stereo), with container time
// `origin_s` (the video's first frame) as pts 0; or, when the file has no audio or it cannot be
// decoded, that reason in the words `nelf play` reports.
OpenedAudio open_file_audio(const std::string& path, double origin_s, bool allow_network, AudioFormat format);

}  // namespace nelf
