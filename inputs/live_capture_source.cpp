// The stereo source of a live capture (inputs/live_capture.hpp): a frame is read when the picture
// changed; each carries the time since the first read.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <memory>

#include "core/ffmpeg_raii.hpp"
#include "core/printable.hpp"
#include "core/user_error.hpp"
#include "inputs/live_capture.hpp"
#include "inputs/stereo_layout.hpp"
#include "inputs/view_bytes.hpp"
#include "inputs/view_regions.hpp"

namespace nelf {
namespace {

// `rect` of the image as the block means the compositor negotiated.
std::vector<std::uint8_t> view_of(const CapturedImage& image, const PixelRect& rect, std::array<int, 2> block) {
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(image.width) * 4;
  return rgba8_block_means(
      &image.pixels[static_cast<std::size_t>(rect.y) * stride + static_cast<std::size_t>(rect.x) * 4], stride,
      rect.width, rect.height, block, image.order);
}

class LiveCaptureSource final : public Source {
 public:
  LiveCaptureSource(const SourceRequest& r, std::unique_ptr<LiveCapture> capture, double frame_rate)
      : input_(r.input), frame_rate_(frame_rate), capture_(std::move(capture)) {
    first_ = capture_->read();
    width_ = first_->width;
    height_ = first_->height;
    origin_ = first_->captured_at;
    LivePictureViews views = live_picture_views(input_, r.layout, r.swap_eyes, width_, height_, r.quiet);
    decision_ = views.decision;
    regions_ = views.regions;
    description_ =
        fmt::format("{}: {}, {}x{}, live, two {}x{} views, layout {}{} ({})", input_, capture_->description(), width_,
                    height_, regions_.left.width, regions_.left.height, to_string(decision_.layout),
                    decision_.swap_eyes ? " swapped" : "", to_string(decision_.rule));
    if (!r.quiet) fmt::print(stderr, "nelf: {}\n", printable(description_));
  }

  SourceInfo info() const override {
    SourceInfo info;
    info.frame_rate = frame_rate_;
    info.live = true;
    info.description = description_;
    info.view = {regions_.left.width, regions_.left.height, regions_.display_aspect};
    return info;
  }

  std::optional<StereoVideoFrame> next() override {
    std::optional<CapturedImage> image = std::move(first_);
    first_.reset();
    while (!image) {
      if (interrupted_ || capture_->closed()) return std::nullopt;
      image = capture_->read_when_changed(std::chrono::milliseconds(50));
    }
    if (image->width != width_ || image->height != height_) *image = scaled(*image);
    StereoVideoFrame frame;
    frame.width = regions_.left.width;
    frame.height = regions_.left.height;
    frame.bits = 8;
    frame.left = view_of(*image, regions_.left, block_);
    frame.right = view_of(*image, regions_.right, block_);
    frame.block = block_;
    frame.aspect = regions_.display_aspect;
    frame.pts_s = std::chrono::duration<double>(image->captured_at - origin_).count();
    // steady_clock is CLOCK_MONOTONIC (libstdc++ on Linux): the clock the game's present times use.
    frame.captured_ns =
        std::chrono::duration_cast<std::chrono::nanoseconds>(image->captured_at.time_since_epoch()).count();
    return frame;
  }

  void interrupt() override { interrupted_ = true; }

  // Any block that fits the view: the means are made here, from the window's RGB.
  ViewFormat negotiate(const ViewFormat& wanted) override {
    const auto& [bx, by] = wanted.block;
    const bool fits = bx >= 1 && by >= 1 && bx <= regions_.left.width && by <= regions_.left.height;
    block_ = fits ? wanted.block : std::array<int, 2>{1, 1};
    return {block_};
  }

 private:
  CapturedImage scaled(const CapturedImage& image) {
    if (!scaler_ || scaled_from_ != std::pair(image.width, image.height) || scaled_order_ != image.order) {
      if (!scaler_)
        fmt::print(stderr, "nelf: {}: the picture is now {}x{}; scaled to {}x{}, the size it started at\n",
                   printable(input_), image.width, image.height, width_, height_);
      const AVPixelFormat format = image.order == ByteOrder::bgrx ? AV_PIX_FMT_BGR0 : AV_PIX_FMT_RGBA;
      scaler_.reset(sws_getContext(image.width, image.height, format, width_, height_, format, SWS_BILINEAR, nullptr,
                                   nullptr, nullptr));
      if (!scaler_) throw UserError(fmt::format("{}: cannot scale the resized window", printable(input_)), 1);
      scaled_from_ = {image.width, image.height};
      scaled_order_ = image.order;
    }
    CapturedImage out;
    out.width = width_;
    out.height = height_;
    out.captured_at = image.captured_at;
    out.order = image.order;
    out.pixels.resize(static_cast<std::size_t>(width_) * height_ * 4);
    const std::uint8_t* src[1] = {image.pixels.data()};
    const int src_stride[1] = {image.width * 4};
    std::uint8_t* dst[1] = {out.pixels.data()};
    const int dst_stride[1] = {width_ * 4};
    sws_scale(scaler_.get(), src, src_stride, 0, image.height, dst, dst_stride);
    return out;
  }

  std::string input_;
  double frame_rate_;
  std::unique_ptr<LiveCapture> capture_;
  std::optional<CapturedImage> first_;
  int width_ = 0, height_ = 0;
  std::chrono::steady_clock::time_point origin_;
  LayoutDecision decision_;
  ViewRegions regions_;
  std::string description_;
  std::atomic<bool> interrupted_{false};
  std::array<int, 2> block_{1, 1};  // what negotiate() set
  ffmpeg::SwsContextPtr scaler_;
  std::pair<int, int> scaled_from_{0, 0};
  ByteOrder scaled_order_ = ByteOrder::rgba;
};

}  // namespace

std::unique_ptr<Source> live_capture_source(const SourceRequest& request,
                                            const std::function<std::unique_ptr<LiveCapture>()>& open,
                                            double frame_rate) {
  if (request.layout == StereoLayout::alt || request.layout == StereoLayout::pair)
    throw UserError(
        fmt::format("layout {} needs a file; a live picture shows both views in one frame", to_string(*request.layout)),
        2);
  return std::make_unique<LiveCaptureSource>(request, open(), frame_rate);
}

}  // namespace nelf
