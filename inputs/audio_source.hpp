#pragma once
// Decoding a media file's audio for playback (`nelf play`): the default audio stream, decoded with
// libavcodec and resampled with libswresample to interleaved float stereo at the output's rate,
// each chunk stamped with its presentation time on the video's timeline (seconds from the same
// origin as Source::pts_s). Damaged packets are skipped and counted, as for video.
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/frames.hpp"

namespace nelf {

// The audio cannot be opened or decoded at all; what() is one line naming the file and the cause.
class AudioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct AudioSourceOptions {
  int sample_rate = 48000;     // of the delivered samples
  double origin_s = 0.0;       // container time that becomes pts 0 (the video's origin)
  bool allow_network = false;  // false: FFmpeg may only use the file and pipe protocols
};

class AudioSource {
 public:
  // True when `path` has an audio stream FFmpeg can decode (false also when it cannot be opened).
  static bool has_audio(const std::string& path, bool allow_network = false);

  // Opens the default audio stream. Throws AudioError when there is none or it cannot be decoded.
  AudioSource(const std::string& path, AudioSourceOptions options = {});
  ~AudioSource();
  AudioSource(AudioSource&&) noexcept;
  AudioSource& operator=(AudioSource&&) noexcept;

  // The next chunk in order, or nullopt at the end of the stream.
  std::optional<AudioChunk> next();
  // The next chunks start at `seconds` (pts timeline); earlier samples of the first one are cut.
  void seek(double seconds);

  int sample_rate() const;
  std::string codec_name() const;
  std::int64_t decode_errors() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nelf
