// The synthetic driver: `synthetic:[scene=planes,duration=S,fps=N,size=WxH,…]`, the built-in clip nelf renders
// itself (inputs/synthetic_source), delivered as whole views.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/user_error.hpp"
#include "inputs/source.hpp"
#include "inputs/synthetic_source.hpp"
#include "inputs/synthetic_tone.hpp"
#include "inputs/view_bytes.hpp"

namespace nelf::drivers {
namespace {

class SyntheticFrameSource final : public Source {
 public:
  SyntheticFrameSource(SyntheticClipSettings settings, double start_s, bool known_depth)
      : clip_(settings),
        next_(static_cast<int>(std::lround(start_s * clip_.settings().fps))),
        known_depth_(known_depth) {}
  std::optional<StereoVideoFrame> next() override {
    if (next_ >= clip_.frame_count()) return std::nullopt;
    const StereoPair pair = clip_.render(next_);
    // The planes scene is still: one disparity for every frame (the compositor then makes its
    // surfaces once); the spheres move, so theirs is traced per frame.
    if (known_depth_ && (clip_.settings().scene != SyntheticScene::planes || !disparity_))
      disparity_ = clip_.disparity(next_);
    StereoVideoFrame f{pair.left.image.width(),
                       pair.left.image.height(),
                       8,
                       view_bytes(pair.left.image, 8),
                       view_bytes(pair.right.image, 8),
                       pair.left.aspect(),
                       static_cast<double>(next_ - first_) / clip_.settings().fps,
                       {1, 1},
                       nullptr,
                       disparity_};
    ++next_;
    return f;
  }
  SourceInfo info() const override {
    const SyntheticClipSettings& s = clip_.settings();
    SourceInfo info;
    info.frame_rate = s.fps;
    info.expected_frames = clip_.frame_count() - first_;
    info.duration_s = static_cast<double>(clip_.frame_count() - first_) / s.fps;
    info.seekable = true;
    info.description = fmt::format("synthetic clip, two {}x{} views at {} fps", s.eye_width, s.eye_height, s.fps);
    info.view = {s.eye_width, s.eye_height, static_cast<double>(s.eye_width) / s.eye_height};
    return info;
  }
  void seek(double seconds) override {
    const int target = first_ + static_cast<int>(std::lround(std::max(0.0, seconds) * clip_.settings().fps));
    next_ = std::clamp(target, first_, clip_.frame_count());
  }
  OpenedAudio open_audio(AudioFormat format) const override {
    return {open_synthetic_tone(clip_.settings(), first_, format), {}};
  }

 private:
  SyntheticClip clip_;
  int next_ = 0;
  int first_ = next_;
  bool known_depth_ = false;
  std::shared_ptr<const StereoDisparity> disparity_;  // the last frame's (known_depth_)
};

}  // namespace

bool accepts_synthetic(const SourceRequest& request) { return is_synthetic_spec(request.input); }

std::unique_ptr<Source> open_synthetic(const SourceRequest& request) {
  try {
    // Filmed for the display it is shown on when the request names one (depth matters), so that
    // the depth of the scene is the depth the viewer sees (matched_to_display); else its own camera.
    SyntheticClipSettings settings = parse_synthetic_spec(request.input);
    if (request.display) settings = matched_to_display(settings, *request.display);
    return std::make_unique<SyntheticFrameSource>(settings, request.start_s.value_or(0.0), request.known_depth);
  } catch (const std::invalid_argument& e) {
    throw UserError(e.what(), 2);
  }
}

}  // namespace nelf::drivers
