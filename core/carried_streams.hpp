#pragma once
// The encoded streams an input hands to a file output to copy as they are: its audio and subtitle
// streams, with what the output needs to set each up, the container's chapters and metadata, and
// the packets in file order on the output's timeline. The source opens them (a file reads itself a
// second time, in step with its video); the encoder takes them without knowing the source.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/ffmpeg_raii.hpp"

namespace nelf {

struct CarriedStream {
  int index = -1;                    // the input's stream index, as its packets name it
  ffmpeg::CodecParametersPtr codec;  // codec type, id, sample rate, extradata …
  AVRational time_base{0, 1};        // of the packets' timestamps
  int disposition = 0;               // AV_DISPOSITION_* (default, forced …)
  ffmpeg::DictionaryPtr metadata;    // language tags, titles
};

struct CarriedChapter {
  std::int64_t id = 0;
  AVRational time_base{0, 1};
  std::int64_t start = 0, end = 0;
  ffmpeg::DictionaryPtr metadata;  // titles
};

// What an output sets up before the first packet.
struct CarriedStreamLayout {
  std::vector<CarriedStream> streams;  // in the input's order
  std::vector<CarriedChapter> chapters;
  ffmpeg::DictionaryPtr metadata;  // the container's (title …)
};

// Copies of the audio and subtitle streams, chapters and metadata of an opened input: they
// outlive it.
CarriedStreamLayout describe_carried_streams(const AVFormatContext& input);

// The chapters of a conversion that starts at input time `origin_s` and ends at output time
// `end_s` (nullopt: the input's end): shifted to output time, those wholly outside left out, the
// others cut to the range (a chapter running at the start point starts at 0), as a player would
// show them in the output.
std::vector<CarriedChapter> chapters_in_range(std::vector<CarriedChapter> chapters, double origin_s,
                                              std::optional<double> end_s);

class CarriedStreams {
 public:
  virtual ~CarriedStreams() = default;
  virtual const CarriedStreamLayout& layout() const = 0;
  // The next packet, in file order, of the streams in `wanted` (CarriedStream::index) that starts
  // at or before output time `until_s` (any time when nullopt), with its timestamps in its
  // stream's time base shifted to output time (0: the video's first frame). Packets before 0 or
  // at or after `end_s` are left out, and so is audio that would play past `end_s`; a subtitle
  // event is cut to [0, end_s) instead (one on screen at 0 starts there). Null when the next
  // wanted packet is later than `until_s` (it is kept for a later call) or the input has no more.
  virtual ffmpeg::PacketPtr next_packet(std::span<const int> wanted, std::optional<double> until_s,
                                        std::optional<double> end_s) = 0;
};

}  // namespace nelf
