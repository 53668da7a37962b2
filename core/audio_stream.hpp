#pragma once
// Decoded sound as a source offers it: chunks of float samples in order at one rate and channel
// count, on the video's timeline, seekable. A media file's audio and the synthetic clip's tone are
// two implementations (inputs/), so the player's sound and convert's encoder take either without
// asking which kind of source they came from.
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "core/frames.hpp"

namespace nelf {

// The audio cannot be opened or decoded at all; what() is one line naming the input and the cause.
class AudioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The samples a caller wants; 0 leaves the choice to the stream (see AudioStream::sample_rate()).
struct AudioFormat {
  int sample_rate = 0;
  int channels = 0;
  int track = 0;  // which of the input's audio tracks (AudioTrack::number); 0: the input's default
};

// One of an input's audio tracks, as a player lists them to choose from.
struct AudioTrack {
  int number = 0;           // 1 for the first audio stream in the file, 2 for the next … (mpv's --aid)
  std::string language;     // ISO 639-2 as the file tags it ("eng", "ger"); "" when untagged
  std::string codec;        // "aac", "ac3"
  int channels = 0;         // the source's
  bool is_default = false;  // the one FFmpeg picks when nobody chooses (the file's default)
};

class AudioStream {
 public:
  virtual ~AudioStream() = default;
  // What next() delivers.
  virtual int sample_rate() const = 0;
  virtual int channels() const = 0;
  // The next chunk in order (pts_s on the video's timeline: 0 is its first frame), or nullopt at
  // the end. Damaged data is skipped and counted; throws AudioError when the stream cannot go on.
  virtual std::optional<AudioChunk> next() = 0;
  // The next chunks start at `seconds` (pts timeline). Throws AudioError when the stream cannot seek.
  virtual void seek(double seconds) = 0;
  // Damaged packets skipped so far.
  virtual std::int64_t decode_errors() const = 0;
  // What is being played, for messages: the codec ("aac", "flac"), or "synthetic tone".
  virtual std::string description() const = 0;
};

// A source's sound, or why there is none in words for the user ("no audio stream", "the audio
// cannot be decoded (…)"): no sound is a state a player reports, not an error.
struct OpenedAudio {
  std::unique_ptr<AudioStream> stream;
  std::string why_not;  // set when stream is null
};

}  // namespace nelf
