// The FFmpeg file driver: a media file in any layout, `alt` (frame-sequential) and `pair` (a second
// file for the right view, --right) included. Last in the table: it takes whatever the others do
// not, and FFmpeg says what it cannot read.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "core/printable.hpp"
#include "core/user_error.hpp"
#include "inputs/audio_source.hpp"
#include "inputs/file_carried_streams.hpp"
#include "inputs/source.hpp"
#include "inputs/video_source.hpp"
#include "inputs/view_regions.hpp"

namespace nelf::drivers {
namespace {

// Copies `rect` of a decoded frame into a tightly packed buffer.
std::vector<std::uint8_t> copy_region(const VideoFrame& frame, const PixelRect& rect) {
  const std::size_t bpp = bytes_per_pixel(frame.bits);
  const auto* base = static_cast<const std::uint8_t*>(frame.pixels());
  std::vector<std::uint8_t> out(static_cast<std::size_t>(rect.width) * rect.height * bpp);
  for (int y = 0; y < rect.height; ++y)
    std::memcpy(&out[static_cast<std::size_t>(y) * rect.width * bpp],
                base + (static_cast<std::size_t>(rect.y + y) * frame.width + rect.x) * bpp,
                static_cast<std::size_t>(rect.width) * bpp);
  return out;
}

class FileFrameSource final : public Source {
 public:
  // `device`: a libavdevice input format, `device_input` what it reads (the device driver's inputs).
  explicit FileFrameSource(const SourceRequest& r, std::string device = {}, std::string device_input = {})
      : path_(r.input),
        allow_network_(r.allow_network),
        device_(std::move(device)),
        source_(device_.empty() ? open(r.input, r) : open_device(r.input, device_input, r, device_)) {
    if (!device_.empty() && r.start_s)
      throw UserError(fmt::format("{}: --start needs a file; a capture device is read live", r.input), 2);
    if (!device_.empty() && r.layout == StereoLayout::pair)
      throw UserError(fmt::format("{}: layout pair needs two files; a capture device is one stream", r.input), 2);
    if (r.start_s) source_.seek(*r.start_s);
    pending_ = source_.next_frame();
    if (!pending_ && r.start_s && source_.info().duration_s && *r.start_s >= *source_.info().duration_s)
      throw UserError(fmt::format("{}: --start {} is past the end of the video ({:.3g} s)", r.input, *r.start_s,
                                  *source_.info().duration_s),
                      1);
    if (!pending_) throw UserError(fmt::format("{}: no video frame could be decoded", r.input), 1);
    // Output time 0 is the first frame delivered, not the requested start: after a seek it can be
    // up to half a frame before or after it, and a first frame stamped below 0 makes muxers shift
    // every stream (Matroska) so that neither starts at 0. The audio is cut at the same point.
    origin_s_ = pending_->pts_s;
    alt_width_ = pending_->width;
    alt_height_ = pending_->height;
    alt_aspect_ = pending_->display_aspect;
    LayoutEvidence evidence;
    evidence.flag = r.layout;
    evidence.metadata = source_.stereo_metadata();
    evidence.width = pending_->width;
    evidence.height = pending_->height;
    evidence.filename = r.input;
    evidence.swap_eyes = r.swap_eyes;
    evidence.display_aspect = pending_->display_aspect;
    evidence.multiview = source_.info().multiview;
    try {
      decision_ = detect_stereo_layout(evidence);
    } catch (const std::exception& e) {
      throw UserError(fmt::format("{}: {}", r.input, e.what()), 1);
    }
    // --quiet hides progress and descriptions, never a warning (as ffmpeg -nostats or mpv --quiet).
    if (!decision_.warning.empty()) fmt::print(stderr, "nelf: warning: {}\n", printable(decision_.warning));
    if (decision_.layout == StereoLayout::pair) {
      if (r.right.empty()) throw UserError("layout pair needs the right view as a second file (--right FILE)", 2);
      right_.emplace(open(r.right, r));
      if (r.start_s) right_->seek(*r.start_s);
      const VideoInfo &a = source_.info(), &b = right_->info();
      if (a.width != b.width || a.height != b.height)
        throw UserError(fmt::format("pair inputs differ in size: {} is {}x{}, {} is {}x{}", r.input, a.width, a.height,
                                    r.right, b.width, b.height),
                        1);
    } else if (decision_.layout != StereoLayout::alt) {
      try {
        regions_ = view_regions(decision_.layout, pending_->width, pending_->height, decision_.swap_eyes,
                                pending_->display_aspect);
      } catch (const LayoutError& e) {
        throw UserError(fmt::format("{}: {}", r.input, e.what()), 1);
      }
    }
    description_ = fmt::format("{}: {}x{} {}, layout {}{} ({})", r.input, source_.info().width, source_.info().height,
                               source_.info().video_codec, to_string(decision_.layout),
                               decision_.swap_eyes ? " swapped" : "", to_string(decision_.rule));
    if (!r.quiet) fmt::print(stderr, "nelf: {}\n", printable(description_));
  }

  std::optional<StereoVideoFrame> next() override {
    auto frame = take();
    if (!frame) return std::nullopt;
    StereoVideoFrame out;
    out.bits = frame->bits;
    out.pts_s = frame->pts_s - origin_s_;
    if (decision_.layout == StereoLayout::alt || decision_.layout == StereoLayout::pair) {
      auto other = decision_.layout == StereoLayout::alt ? take() : right_->next_frame();
      if (!other) return std::nullopt;  // an unpaired last view is dropped
      if (other->width != frame->width || other->height != frame->height || other->bits != frame->bits)
        throw UserError(fmt::format("{}: the two views of a frame differ in size", path_), 1);
      const PixelRect whole{0, 0, frame->width, frame->height};
      out.width = frame->width;
      out.height = frame->height;
      out.aspect = frame->display_aspect;
      if (frame->reduced.empty() != other->reduced.empty())
        throw UserError(fmt::format("{}: the two views of a frame differ in size", path_), 1);
      if (!frame->reduced.empty()) {
        out.left = std::move(frame->reduced.at(0));
        out.right = std::move(other->reduced.at(0));
        out.block = block_;
      } else {
        out.left = copy_region(*frame, whole);
        out.right = copy_region(*other, whole);
      }
      if (decision_.swap_eyes) std::swap(out.left, out.right);
    } else {
      if (frame->width != width() || frame->height != height())
        throw UserError(fmt::format("{}: the frame size changed mid-stream ({}x{} to {}x{})", path_, width(), height(),
                                    frame->width, frame->height),
                        1);
      out.width = regions_.left.width;
      out.height = regions_.left.height;
      out.aspect = regions_.display_aspect;
      if (!frame->reduced.empty()) {
        out.left = std::move(frame->reduced.at(0));
        out.right = std::move(frame->reduced.at(1));
        out.block = block_;
      } else {
        out.left = copy_region(*frame, regions_.left);
        out.right = copy_region(*frame, regions_.right);
      }
    }
    return out;
  }

  // A device cannot be opened a second time for its sound while its video is read.
  OpenedAudio open_audio(AudioFormat format) const override {
    if (!device_.empty()) return {nullptr, "a capture device's sound is not read"};
    return open_file_audio(path_, origin_s_, allow_network_, format);
  }
  std::vector<AudioTrack> audio_tracks() const override {
    if (!device_.empty()) return {};
    return file_audio_tracks(path_, allow_network_);
  }
  std::unique_ptr<CarriedStreams> open_carried_streams() const override {
    if (!device_.empty()) return nullptr;
    return open_file_carried_streams(path_, origin_s_, allow_network_);
  }
  void interrupt() override { source_.interrupt(); }
  SourceInfo info() const override {
    const VideoInfo& video = source_.info();
    SourceInfo info;
    const double fps = video.fps > 0 ? video.fps : 25.0;
    info.frame_rate = decision_.layout == StereoLayout::alt ? fps / 2 : fps;
    std::optional<double> frames;
    if (video.frame_count)
      frames = static_cast<double>(*video.frame_count);
    else if (video.duration_s && video.fps > 0)
      frames = *video.duration_s * video.fps;
    if (frames && !video.live) {
      if (decision_.layout == StereoLayout::alt) *frames /= 2;
      info.expected_frames = static_cast<long>(std::lround(*frames));
    }
    info.live = video.live;
    if (video.duration_s && !video.live)
      info.duration_s = std::max(0.0, *video.duration_s - (origin_s_ - video.start_time_s));
    info.seekable = video.seekable && (!right_ || right_->info().seekable);
    info.description = description_;
    info.view = view_geometry();
    return info;
  }
  void seek(double seconds) override {
    if (!device_.empty()) throw UserError(fmt::format("{}: a capture device cannot seek", path_), 1);
    // The source's own clock starts at its start time; pts_s 0 is origin_s_.
    const double from_start = std::max(0.0, origin_s_ - source_.info().start_time_s + seconds);
    pending_.reset();
    try {
      source_.seek(from_start);
      if (right_) right_->seek(from_start);
    } catch (const VideoError& e) {
      throw UserError(e.what(), 1);
    }
  }
  // The compositor's first prefilter pass (a block mean over the view) done by swscale while it
  // converts the decoded YUV: the GL stage then uploads and reads 1/block² of the texels, and the
  // full-resolution RGBA frame is never made. VideoSource keeps the regions across seeks.
  ViewFormat negotiate(const ViewFormat& format) override {
    if (decision_.layout == StereoLayout::pair) return {block_};  // two decoders: whole frames
    const bool whole = decision_.layout == StereoLayout::alt;
    const PixelRect left = whole ? PixelRect{0, 0, alt_width_, alt_height_} : regions_.left;
    const PixelRect right = whole ? left : regions_.right;
    std::array<int, 2> block = format.block;
    std::vector<ReducedRegion> wanted;
    if (block[0] > 1 || block[1] > 1) {
      wanted.push_back({left.x, left.y, left.width, left.height, block[0], block[1]});
      if (!whole) wanted.push_back({right.x, right.y, right.width, right.height, block[0], block[1]});
    }
    try {
      if (!source_.reduce_regions(std::move(wanted), format.max_bits)) {
        block = {1, 1};
        source_.reduce_regions({});  // whole frames always work
      }
      if (block != block_ && pending_) pending_ = source_.convert_last();
    } catch (const VideoError& e) {
      throw UserError(e.what(), 1);
    }
    block_ = block;
    return {block_, format.max_bits};
  }
  std::int64_t lost_frames() const override {
    return source_.stats().problems() + (right_ ? right_->stats().problems() : 0);
  }

 private:
  static VideoSource open(const std::string& path, const SourceRequest& r) {
    try {
      return VideoSource(path, VideoSourceOptions{r.allow_network, true, r.max_pixels, {}});
    } catch (const VideoError& e) {
      throw UserError(e.what(), 1);
    }
  }
  // The device's messages name the input as the user wrote it (v4l2:/dev/video0), not what the
  // device was given (/dev/video0).
  static VideoSource open_device(const std::string& spec, const std::string& device_input, const SourceRequest& r,
                                 const std::string& device) {
    try {
      return VideoSource(device_input,
                         VideoSourceOptions{r.allow_network, true, r.max_pixels, device, r.device_options});
    } catch (const VideoError& e) {
      std::string what = e.what();
      if (what.rfind(device_input + ": ", 0) == 0) what.erase(0, device_input.size() + 2);
      throw UserError(fmt::format("{}: {}", spec, what), 1);
    }
  }
  std::optional<VideoFrame> take() {
    if (pending_) return std::exchange(pending_, std::nullopt);
    try {
      return source_.next_frame();
    } catch (const VideoError& e) {
      throw UserError(e.what(), 1);
    }
  }
  ViewGeometry view_geometry() const {
    if (decision_.layout == StereoLayout::alt || decision_.layout == StereoLayout::pair)
      return {alt_width_, alt_height_, alt_aspect_};
    return {regions_.left.width, regions_.left.height, regions_.display_aspect};
  }
  int width() const { return source_.info().width; }
  int height() const { return source_.info().height; }

  std::string path_;
  bool allow_network_;  // for the audio and carried streams, opened on their own
  std::string device_;  // a capture device's input format; empty for a file
  std::string description_;
  VideoSource source_;
  std::optional<VideoSource> right_;
  std::optional<VideoFrame> pending_;
  LayoutDecision decision_;
  ViewRegions regions_;
  int alt_width_ = 0, alt_height_ = 0;  // layouts alt and pair: each frame is a whole view of this size
  double alt_aspect_ = 0.0;
  double origin_s_ = 0.0;
  std::array<int, 2> block_{1, 1};  // what negotiate() set
};

}  // namespace

bool accepts_file(const SourceRequest& /*request*/) { return true; }

std::unique_ptr<Source> open_file(const SourceRequest& request) { return std::make_unique<FileFrameSource>(request); }

std::unique_ptr<Source> open_ffmpeg_device(const SourceRequest& request, const std::string& device,
                                           const std::string& device_input) {
  return std::make_unique<FileFrameSource>(request, device, device_input);
}

}  // namespace nelf::drivers
