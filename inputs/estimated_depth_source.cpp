#include "inputs/estimated_depth_source.hpp"

#include <utility>

namespace nelf {
namespace {

class EstimatedDepthSource final : public Source {
 public:
  EstimatedDepthSource(std::unique_ptr<Source> source, bool keep_known, StereoMatcherSettings settings)
      : source_(std::move(source)), keep_known_(keep_known), matcher_(settings) {}

  SourceInfo info() const override { return source_->info(); }
  std::optional<StereoVideoFrame> next() override {
    std::optional<StereoVideoFrame> frame = source_->next();
    if (frame && !(keep_known_ && frame->disparity)) frame->disparity = matcher_.estimate(*frame);
    return frame;
  }
  void seek(double seconds) override {
    source_->seek(seconds);
    matcher_.reset();  // the next frame is not the previous one's successor
  }
  ViewFormat negotiate(const ViewFormat& wanted) override { return source_->negotiate(wanted); }
  OpenedAudio open_audio(AudioFormat format) const override { return source_->open_audio(format); }
  std::vector<AudioTrack> audio_tracks() const override { return source_->audio_tracks(); }
  std::unique_ptr<CarriedStreams> open_carried_streams() const override { return source_->open_carried_streams(); }
  std::int64_t lost_frames() const override { return source_->lost_frames(); }
  void interrupt() override { source_->interrupt(); }
  void refresh_at(std::int64_t refresh_ns, std::int64_t period_ns) override {
    source_->refresh_at(refresh_ns, period_ns);
  }

 private:
  std::unique_ptr<Source> source_;
  bool keep_known_;
  StereoMatcher matcher_;
};

}  // namespace

std::unique_ptr<Source> with_estimated_depth(std::unique_ptr<Source> source, bool keep_known,
                                             StereoMatcherSettings settings) {
  return std::make_unique<EstimatedDepthSource>(std::move(source), keep_known, settings);
}

}  // namespace nelf
