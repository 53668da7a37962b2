// The still driver: one stereo photo (JPS, MPO, any image OpenImageIO reads, or two with --right) as
// a source of one frame, read with load_still: `nelf play` and `nelf convert` read stills alike.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>

#include "core/printable.hpp"
#include "core/user_error.hpp"
#include "inputs/source.hpp"
#include "inputs/still_source.hpp"
#include "inputs/view_bytes.hpp"

namespace nelf::drivers {
namespace {

// FFmpeg's image demuxer gives a still 25 frames per second: play showed a still for that one frame
// period while FFmpeg read stills, and shows it as long now.
constexpr double kStillFrameRate = 25.0;

// 8 bits when they hold every value exactly (an 8-bit file: OpenImageIO reads k as k/255), else 16.
int bits_for(const Image& left, const Image& right) {
  for (const Image* image : {&left, &right}) {
    const float* p = image->data();
    const std::size_t n = static_cast<std::size_t>(image->width()) * image->height() * 4;
    for (std::size_t i = 0; i < n; ++i) {
      const float v = std::clamp(p[i], 0.f, 1.f) * 255.f;
      if (std::abs(v - std::round(v)) > 1e-3f) return 16;
    }
  }
  return 8;
}

class StillFrameSource final : public Source {
 public:
  explicit StillFrameSource(const SourceRequest& r) {
    if (r.layout == StereoLayout::alt)
      throw UserError("layout alt (frame-sequential) needs a video; a still holds one view per frame", 2);
    StillOptions options;
    options.layout = r.layout;
    if (!r.right.empty()) options.right = r.right;
    options.swap_eyes = r.swap_eyes;
    options.max_pixels = r.max_pixels;
    StillStereo still;
    try {
      still = load_still(r.input, options);
    } catch (const StillError& e) {
      throw UserError(e.what(), 1);
    }
    if (!still.decision.warning.empty()) fmt::print(stderr, "nelf: warning: {}\n", printable(still.decision.warning));
    views_ = std::make_shared<const StereoPair>(std::move(still.views));
    const Image& left = views_->left.image;
    description_ = fmt::format("{}: still image, two {}x{} views, layout {}{} ({})", r.input, left.width(),
                               left.height(), to_string(still.decision.layout),
                               still.decision.swap_eyes ? " swapped" : "", to_string(still.decision.rule));
    if (!r.quiet) fmt::print(stderr, "nelf: {}\n", printable(description_));
    if (r.start_s) seek(*r.start_s);
  }

  SourceInfo info() const override {
    SourceInfo info;
    info.frame_rate = kStillFrameRate;
    info.duration_s = 1.0 / kStillFrameRate;
    info.expected_frames = 1;
    info.seekable = true;
    info.still = true;
    info.description = description_;
    info.view = {views_->left.image.width(), views_->left.image.height(), views_->left.aspect()};
    return info;
  }

  std::optional<StereoVideoFrame> next() override {
    if (delivered_) return std::nullopt;
    delivered_ = true;
    StereoVideoFrame frame;
    frame.width = views_->left.image.width();
    frame.height = views_->left.image.height();
    frame.bits = bits_for(views_->left.image, views_->right.image);
    frame.left = view_bytes(views_->left.image, frame.bits);
    frame.right = view_bytes(views_->right.image, frame.bits);
    frame.aspect = views_->left.aspect();
    frame.exact_views = views_;
    return frame;
  }

  // The one frame lasts one frame period: a seek into it shows it again, one past it ends the source.
  void seek(double seconds) override { delivered_ = seconds >= 1.0 / kStillFrameRate; }

 private:
  std::shared_ptr<const StereoPair> views_;
  std::string description_;
  bool delivered_ = false;
};

}  // namespace

bool accepts_still(const SourceRequest& request) { return is_still_image_name(request.input); }

std::unique_ptr<Source> open_still(const SourceRequest& request) { return std::make_unique<StillFrameSource>(request); }

}  // namespace nelf::drivers
