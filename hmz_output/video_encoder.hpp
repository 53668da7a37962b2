#pragma once
// The encoder sink: packed RGBA frames in, a video file out (FFmpeg), with the source's audio,
// subtitle and chapter streams (core/carried_streams.hpp) carried over where the container takes
// them. The file is written under a temporary name in the destination directory and renamed by
// finish(); an encoder that is destroyed unfinished (error, Ctrl-C) removes its temporary file, so
// no half-written output remains.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/carried_streams.hpp"
#include "core/frames.hpp"

struct AVPacket;

namespace nelf {

struct EncoderSettings {
  std::string codec = "h264";  // h264, hevc, ffv1, or any FFmpeg encoder name
  std::optional<int> crf;      // quality for x264/x265 (default 18)
  std::string preset = "medium";
  bool overwrite = false;  // -y
  bool audio = true;       // carry the source's audio streams
  // The file's bits a channel: 8 (what plays everywhere), or more: 10 where the codec allows.
  int bits = 8;
  // --duration: the carried chapters end there at the latest (they come at output time).
  std::optional<double> carried_end_s;
};

class VideoEncoder {
 public:
  // `carried` (optional): the source's streams, chapters and metadata to carry over (its packets
  // then come through write_source_packet); `frame_rate` is the nominal rate (num/den) used as the
  // stream's rate; timestamps come from each frame.
  VideoEncoder(const std::filesystem::path& output, int width, int height, int frame_rate_num, int frame_rate_den,
               const EncoderSettings& settings, const CarriedStreamLayout* carried = nullptr);
  ~VideoEncoder();
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  void write_video(const PackedFrame& frame);
  // A packet of source stream `source_stream` (CarriedStream::index) in that stream's time base;
  // ignored when that stream is not carried.
  void write_source_packet(AVPacket* packet, int source_stream);
  // A generated audio track (e.g. the synthetic source's tone), encoded as AAC. Call before the first
  // write; then pass interleaved float samples (−1..1) in order.
  void add_audio_track(int sample_rate, int channels);
  void write_audio(const float* interleaved, int sample_count);

  // Flushes, writes the trailer and renames the temporary file to the output path.
  void finish();

  const std::string& codec_name() const;
  const std::string& pixel_format_name() const;
  // Source streams carried (CarriedStream::index), in order.
  std::vector<int> carried_streams() const;

 private:
  struct State;
  static void convert_with_swscale(State& s, const PackedFrame& in);
  std::unique_ptr<State> state_;
};

}  // namespace nelf
