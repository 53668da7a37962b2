// An encoded video file (hmz_output/video_encoder.hpp), with the source's own streams copied when it
// has them (a file's audio, subtitles and chapters), else its decoded sound (the synthetic clip's
// tone) encoded.
#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

extern "C" {
#include <libavutil/rational.h>
}

#include "core/user_error.hpp"
#include "hmz_output/frame_sink.hpp"

namespace nelf {
namespace {

class EncodedFileSink final : public FrameSink {
 public:
  explicit EncodedFileSink(FrameSinkRequest r)
      : output_(r.output),
        frame_rate_(r.frame_rate),
        carried_(std::move(r.carried)),
        audio_(carried_ ? nullptr : std::move(r.audio)),
        end_s_(r.duration_s) {
    EncoderSettings settings = r.encoder;  // its bits: the file's (--bits), whatever the frames'
    settings.carried_end_s = r.duration_s;
    const AVRational rate = av_d2q(r.frame_rate, 100000);
    try {
      encoder_.emplace(r.output, r.width, r.height, rate.num, rate.den, settings,
                       carried_ ? &carried_->layout() : nullptr);
    } catch (const std::invalid_argument& e) {
      throw UserError(e.what(), 2);
    } catch (const std::runtime_error& e) {
      throw UserError(e.what(), 1);
    }
    if (audio_) encoder_->add_audio_track(audio_->sample_rate(), audio_->channels());
    if (carried_) carried_indices_ = encoder_->carried_streams();
  }
  void write(const PackedFrame& frame) override {
    encoder_->write_video(frame);
    last_end_s_ = frame.pts_seconds + 1.0 / frame_rate_;
    // Only what starts before this frame ends: the conversion may stop at any frame (--frames, a
    // damaged input), and audio already written past that point could not be taken back.
    carry_until(last_end_s_ - 1e-6, end_s_);
    if (audio_) encode_audio_until(std::llround(last_end_s_ * audio_->sample_rate()));
  }
  void finish() override {
    // Audio ends with the video (what was converted), not with the source.
    carry_until(last_end_s_, last_end_s_);
    encoder_->finish();
  }
  std::string description() const override { return output_; }

 private:
  // The carried packets up to output time `until_s`, before `end_s`.
  void carry_until(std::optional<double> until_s, std::optional<double> end_s) {
    if (!carried_) return;
    while (auto packet = carried_->next_packet(carried_indices_, until_s, end_s))
      encoder_->write_source_packet(packet.get(), packet->stream_index);
  }
  // The decoded sound up to its first `until` sample frames in all (a stream that ends early ends
  // the track there). It follows on from 0 as the chunks come; their own times are not read.
  void encode_audio_until(std::int64_t until) {
    while (audio_written_ < until) {
      if (pending_offset_ >= pending_.frames()) {
        std::optional<AudioChunk> chunk;
        try {
          chunk = audio_->next();
        } catch (const AudioError& e) {
          throw UserError(e.what(), 1);
        }
        if (!chunk) return;
        pending_ = std::move(*chunk);
        pending_offset_ = 0;
        continue;
      }
      const std::int64_t count = std::min(until - audio_written_, pending_.frames() - pending_offset_);
      encoder_->write_audio(pending_.samples.data() + pending_offset_ * pending_.channels, static_cast<int>(count));
      pending_offset_ += count;
      audio_written_ += count;
    }
  }

  std::string output_;
  double frame_rate_;
  std::unique_ptr<CarriedStreams> carried_;
  std::vector<int> carried_indices_;  // what the encoder carries of carried_
  std::unique_ptr<AudioStream> audio_;
  AudioChunk pending_;  // decoded and not all encoded yet, from pending_offset_ on
  std::int64_t pending_offset_ = 0;
  std::optional<VideoEncoder> encoder_;
  std::optional<double> end_s_;
  double last_end_s_ = 0.0;
  std::int64_t audio_written_ = 0;  // sample frames
};

}  // namespace

std::unique_ptr<FrameSink> open_encoded_file_sink(FrameSinkRequest request) {
  return std::make_unique<EncodedFileSink>(std::move(request));
}

}  // namespace nelf
