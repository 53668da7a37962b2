#include "inputs/synthetic_tone.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace nelf {
namespace {

class SyntheticTone final : public AudioStream {
 public:
  SyntheticTone(SyntheticClipSettings settings, int first_frame, int channels) : clip_(settings), channels_(channels) {
    const SyntheticClipSettings& s = clip_.settings();
    // Counted in whole samples as convert always has: frame f starts at sample f * rate / fps.
    first_ = static_cast<std::int64_t>(first_frame) * s.audio_rate / s.fps;
    // Up to the end of the last frame, rounded up: never short of what a converted frame spans.
    const std::int64_t frames = std::max(0, clip_.frame_count() - first_frame);
    end_ = (frames * s.audio_rate + s.fps - 1) / s.fps;
  }

  int sample_rate() const override { return clip_.settings().audio_rate; }
  int channels() const override { return channels_; }
  std::optional<AudioChunk> next() override {
    if (next_ >= end_) return std::nullopt;
    const int count = static_cast<int>(std::min<std::int64_t>(kChunkFrames, end_ - next_));
    const std::vector<float> mono = clip_.audio(first_ + next_, count);
    AudioChunk chunk{static_cast<double>(next_) / sample_rate(), {}, channels_};
    chunk.samples.reserve(mono.size() * static_cast<std::size_t>(channels_));
    for (float v : mono) chunk.samples.insert(chunk.samples.end(), static_cast<std::size_t>(channels_), v);
    next_ += count;
    return chunk;
  }
  void seek(double seconds) override {
    next_ = std::clamp<std::int64_t>(std::llround(std::max(0.0, seconds) * sample_rate()), 0, end_);
  }
  std::int64_t decode_errors() const override { return 0; }
  std::string description() const override { return "synthetic tone"; }

 private:
  static constexpr int kChunkFrames = 1024;
  SyntheticClip clip_;
  int channels_;
  std::int64_t first_ = 0, end_ = 0, next_ = 0;  // samples; next_ and end_ counted from first_
};

}  // namespace

std::unique_ptr<AudioStream> open_synthetic_tone(const SyntheticClipSettings& settings, int first_frame,
                                                 AudioFormat format) {
  SyntheticClipSettings tone = settings;
  if (format.sample_rate > 0) tone.audio_rate = format.sample_rate;
  const int channels = format.channels > 0 ? format.channels : 1;
  return std::make_unique<SyntheticTone>(tone, first_frame, channels);
}

}  // namespace nelf
