#include "app/convert_video.hpp"

#include <fmt/format.h>
#include <fmt/printf.h>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <exception>
#include <future>
#include <mutex>
#include <regex>
#include <thread>

extern "C" {
#include <libavformat/avformat.h>
}

#include "app/commands.hpp"
#include "compositor/gl_compositor.hpp"
#include "hmz_output/image_sink.hpp"
#include "hmz_output/packing.hpp"
#include "hmz_output/progress.hpp"
#include "inputs/bounded_queue.hpp"
#include "inputs/ffmpeg_raii.hpp"
#include "inputs/synthetic_source.hpp"
#include "inputs/video_source.hpp"
#include "inputs/view_regions.hpp"

namespace nelf::app {

namespace {

// Set by SIGINT/SIGTERM while a conversion runs; every stage polls it.
std::atomic<bool> interrupted{false};
extern "C" void on_interrupt(int) { interrupted.store(true); }

// Installs the handlers for the lifetime of the conversion and restores the previous ones.
class InterruptGuard {
 public:
  InterruptGuard() {
    interrupted.store(false);
    struct sigaction action {};
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, &previous_int_);
    sigaction(SIGTERM, &action, &previous_term_);
  }
  ~InterruptGuard() {
    sigaction(SIGINT, &previous_int_, nullptr);
    sigaction(SIGTERM, &previous_term_, nullptr);
  }
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction previous_int_ {};
  struct sigaction previous_term_ {};
};

// Both views of one stereo frame, as tightly packed RGBA of `bits` per channel: width×height
// pixels, or, when `block` is more than 1×1, the means of block[0]×block[1] pixels (the
// compositor's prefilter block, done while converting from YUV).
struct StereoVideoFrame {
  int width = 0, height = 0, bits = 8;
  std::vector<std::uint8_t> left, right;
  double aspect = 0.0;
  double pts_s = 0.0;  // output time, from 0
  std::array<int, 2> block{1, 1};
};

std::size_t bytes_per_pixel(int bits) { return bits > 8 ? 8 : 4; }

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

std::vector<std::uint8_t> to_rgba8(const Image& image) {
  std::vector<std::uint8_t> out(static_cast<std::size_t>(image.width()) * image.height() * 4);
  const float* p = image.data();
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = static_cast<std::uint8_t>(std::lround(std::clamp(p[i], 0.f, 1.f) * 255.f));
  return out;
}

// A source of stereo frames: a decoded file (any layout, pair, alt) or the synthetic clip.
class StereoFrameSource {
 public:
  virtual ~StereoFrameSource() = default;
  virtual std::optional<StereoVideoFrame> next() = 0;
  virtual double frame_rate() const = 0;
  virtual std::optional<long> expected_frames() const = 0;
  // The container whose audio/subtitles are carried over (opened separately), if any.
  virtual std::string audio_path() const { return {}; }
  virtual bool has_generated_audio() const { return false; }
  virtual std::vector<float> generated_audio(std::int64_t, int) const { return {}; }
  virtual int generated_audio_rate() const { return 0; }
  virtual void finish_checks(bool /*strict*/) {}
  // Source time (s) that becomes output time 0.
  virtual double origin_s() const { return 0.0; }
};

class SyntheticFrameSource final : public StereoFrameSource {
 public:
  SyntheticFrameSource(const std::string& spec, double start_s)
      : clip_(parse_synthetic_spec(spec)), next_(static_cast<int>(std::lround(start_s * clip_.settings().fps))) {}
  std::optional<StereoVideoFrame> next() override {
    if (next_ >= clip_.frame_count()) return std::nullopt;
    const StereoPair pair = clip_.render(next_);
    StereoVideoFrame f{pair.left.image.width(),
                       pair.left.image.height(),
                       8,
                       to_rgba8(pair.left.image),
                       to_rgba8(pair.right.image),
                       pair.left.aspect(),
                       static_cast<double>(next_ - first_) / clip_.settings().fps,
                       {1, 1}};
    ++next_;
    return f;
  }
  double frame_rate() const override { return clip_.settings().fps; }
  std::optional<long> expected_frames() const override { return clip_.frame_count() - first_; }
  bool has_generated_audio() const override { return true; }
  std::vector<float> generated_audio(std::int64_t first, int count) const override {
    return clip_.audio(first + static_cast<std::int64_t>(first_) * clip_.settings().audio_rate / clip_.settings().fps,
                       count);
  }
  int generated_audio_rate() const override { return clip_.settings().audio_rate; }

 private:
  SyntheticClip clip_;
  int next_ = 0;
  int first_ = next_;
};

class FileFrameSource final : public StereoFrameSource {
 public:
  FileFrameSource(const VideoConvertRequest& r) : path_(r.input), source_(open(r.input, r.allow_network)) {
    if (r.start_s) source_.seek(*r.start_s);
    pending_ = source_.next_frame();
    if (!pending_ && r.start_s && source_.info().duration_s && *r.start_s >= *source_.info().duration_s)
      throw UserError(fmt::format("{}: --start {} is past the end of the video ({:.3g} s)", r.input, *r.start_s,
                                  *source_.info().duration_s),
                      1);
    if (!pending_) throw UserError(fmt::format("{}: no video frame could be decoded", r.input), 1);
    origin_s_ = source_.info().start_time_s + r.start_s.value_or(0.0);
    LayoutEvidence evidence;
    evidence.flag = r.layout;
    evidence.metadata = source_.stereo_metadata();
    evidence.width = pending_->width;
    evidence.height = pending_->height;
    evidence.filename = r.input;
    evidence.swap_eyes = r.swap_eyes;
    evidence.display_aspect = pending_->display_aspect;
    try {
      decision_ = detect_stereo_layout(evidence);
    } catch (const std::exception& e) {
      throw UserError(fmt::format("{}: {}", r.input, e.what()), 1);
    }
    if (!decision_.warning.empty() && !r.quiet) fmt::print(stderr, "nelf: warning: {}\n", decision_.warning);
    if (decision_.layout == StereoLayout::pair) {
      if (r.right.empty()) throw UserError("layout pair needs the right view as a second file (--right FILE)", 2);
      right_.emplace(open(r.right, r.allow_network));
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
    reduce_while_converting(r);
    if (!r.quiet)
      fmt::print(stderr, "nelf: {}: {}x{} {}, layout {}{} ({})\n", r.input, source_.info().width, source_.info().height,
                 source_.info().video_codec, to_string(decision_.layout), decision_.swap_eyes ? " swapped" : "",
                 to_string(decision_.rule));
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
      if (reduced()) {
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
      if (reduced()) {
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

  double frame_rate() const override {
    const double fps = source_.info().fps > 0 ? source_.info().fps : 25.0;
    return decision_.layout == StereoLayout::alt ? fps / 2 : fps;
  }
  std::optional<long> expected_frames() const override {
    const VideoInfo& info = source_.info();
    std::optional<double> frames;
    if (info.frame_count)
      frames = static_cast<double>(*info.frame_count);
    else if (info.duration_s && info.fps > 0)
      frames = *info.duration_s * info.fps;
    if (!frames) return std::nullopt;
    if (decision_.layout == StereoLayout::alt) *frames /= 2;
    return static_cast<long>(std::lround(*frames));
  }
  std::string audio_path() const override { return path_; }
  double origin_s() const override { return origin_s_; }
  void finish_checks(bool strict) override {
    const std::int64_t lost = source_.stats().problems() + (right_ ? right_->stats().problems() : 0);
    if (lost == 0) return;
    const std::string what = fmt::format("{}: damaged or truncated: {} frame(s) lost or damaged", path_, lost);
    if (strict) throw UserError(what + " (--strict)", 1);
    fmt::print(stderr, "nelf: warning: {}; converted what decodes\n", what);
  }

 private:
  static VideoSource open(const std::string& path, bool allow_network) {
    try {
      return VideoSource(path, VideoSourceOptions{allow_network, true});
    } catch (const VideoError& e) {
      throw UserError(e.what(), 1);
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
  int width() const { return source_.info().width; }
  int height() const { return source_.info().height; }
  bool reduced() const { return block_[0] > 1 || block_[1] > 1; }

  // The compositor's first prefilter pass (a block mean over the view) done by swscale while it
  // converts the decoded YUV: the GL stage then uploads and reads 1/block² of the texels. Only
  // when both eyes want the same block, and the stream allows it (VideoSource::reduce_regions);
  // otherwise whole RGBA frames as before. Pair inputs (two decoders) always take whole frames.
  void reduce_while_converting(const VideoConvertRequest& r) {
    if (decision_.layout == StereoLayout::pair) return;
    const bool whole = decision_.layout == StereoLayout::alt;
    const PixelRect left = whole ? PixelRect{0, 0, pending_->width, pending_->height} : regions_.left;
    const PixelRect right = whole ? left : regions_.right;
    const double aspect = whole ? pending_->display_aspect : regions_.display_aspect;
    const auto block = prefilter_block(r.profile, r.compositor, Eye::left, left.width, left.height, aspect);
    if (block != prefilter_block(r.profile, r.compositor, Eye::right, left.width, left.height, aspect)) return;
    if (block[0] == 1 && block[1] == 1) return;
    std::vector<ReducedRegion> wanted{{left.x, left.y, left.width, left.height, block[0], block[1]}};
    if (!whole) wanted.push_back({right.x, right.y, right.width, right.height, block[0], block[1]});
    if (!source_.reduce_regions(std::move(wanted))) return;
    block_ = block;
    pending_ = source_.convert_last();
  }

  std::string path_;
  VideoSource source_;
  std::optional<VideoSource> right_;
  std::optional<VideoFrame> pending_;
  LayoutDecision decision_;
  ViewRegions regions_;
  double origin_s_ = 0.0;
  std::array<int, 2> block_{1, 1};
};

// Where packed frames go: an encoded file or an image sequence.
class FrameSink {
 public:
  virtual ~FrameSink() = default;
  virtual void write(const PackedFrame& frame) = 0;
  virtual void finish() = 0;
};

// Carries the source's audio and subtitles: a second demuxer on the same file, read in step with
// the video so the muxer's interleaving buffer stays small.
class SourcePacketCarrier {
 public:
  SourcePacketCarrier(const std::string& path, double origin_s, bool allow_network) : origin_s_(origin_s) {
    AVDictionary* raw_options = nullptr;
    if (!allow_network) av_dict_set(&raw_options, "protocol_whitelist", "file,pipe", 0);
    AVFormatContext* raw = nullptr;
    const std::string url = path.find("://") == std::string::npos ? "file:" + path : path;
    const int opened = avformat_open_input(&raw, url.c_str(), nullptr, &raw_options);
    ffmpeg::DictionaryPtr unused(raw_options);
    if (opened < 0)
      throw UserError(fmt::format("{}: cannot reopen for audio: {}", path, ffmpeg::error_string(opened)), 1);
    format_.reset(raw);
    if (avformat_find_stream_info(format_.get(), nullptr) < 0)
      throw UserError(fmt::format("{}: cannot read stream information", path), 1);
    if (origin_s > format_->start_time / static_cast<double>(AV_TIME_BASE) + 0.001)
      av_seek_frame(format_.get(), -1, static_cast<std::int64_t>(origin_s * AV_TIME_BASE), AVSEEK_FLAG_BACKWARD);
  }
  AVFormatContext* format() const { return format_.get(); }

  // Writes the carried packets up to output time `until_s` (all of them when nullopt, up to `end_s`).
  void carry_until(VideoEncoder& encoder, std::optional<double> until_s, std::optional<double> end_s) {
    const auto carried = encoder.carried_streams();
    if (carried.empty() || done_) return;
    for (;;) {
      if (!packet_) {
        packet_.reset(av_packet_alloc());
        if (av_read_frame(format_.get(), packet_.get()) < 0) {
          done_ = true;
          packet_.reset();
          return;
        }
      }
      const AVStream* stream = format_->streams[packet_->stream_index];
      const std::int64_t ts = packet_->pts != AV_NOPTS_VALUE ? packet_->pts : packet_->dts;
      const double t = ts == AV_NOPTS_VALUE ? 0.0 : ts * av_q2d(stream->time_base) - origin_s_;
      if (until_s && t > *until_s) return;  // keep it for later
      const bool wanted = std::find(carried.begin(), carried.end(), packet_->stream_index) != carried.end();
      if (wanted && t >= -1e-6 && (!end_s || t < *end_s)) {
        // Shift to output time (the conversion starts at 0).
        const std::int64_t shift = llround(origin_s_ / av_q2d(stream->time_base));
        if (packet_->pts != AV_NOPTS_VALUE) packet_->pts -= shift;
        if (packet_->dts != AV_NOPTS_VALUE) packet_->dts -= shift;
        encoder.write_source_packet(packet_.get(), packet_->stream_index);
      }
      packet_.reset();
    }
  }

 private:
  ffmpeg::FormatContextPtr format_;
  ffmpeg::PacketPtr packet_;
  double origin_s_;
  bool done_ = false;
};

class EncodedFileSink final : public FrameSink {
 public:
  EncodedFileSink(const VideoConvertRequest& r, StereoFrameSource& source, int width, int height, int bits,
                  double origin_s)
      : source_(source) {
    if (!source.audio_path().empty() && r.encoder.audio)
      carrier_.emplace(source.audio_path(), origin_s, r.allow_network);
    EncoderSettings settings = r.encoder;
    settings.bits = bits;
    const AVRational rate = av_d2q(source.frame_rate(), 100000);
    try {
      encoder_.emplace(r.output, width, height, rate.num, rate.den, settings, carrier_ ? carrier_->format() : nullptr);
    } catch (const std::invalid_argument& e) {
      throw UserError(e.what(), 2);
    } catch (const std::runtime_error& e) {
      throw UserError(e.what(), 1);
    }
    if (source.has_generated_audio() && r.encoder.audio) {
      encoder_->add_audio_track(source.generated_audio_rate(), 1);
      generated_rate_ = source.generated_audio_rate();
    }
    end_s_ = r.duration_s;
  }
  void write(const PackedFrame& frame) override {
    encoder_->write_video(frame);
    last_end_s_ = frame.pts_seconds + 1.0 / source_.frame_rate();
    // Only what starts before this frame ends: the conversion may stop at any frame (--frames, a
    // damaged input), and audio already written past that point could not be taken back.
    if (carrier_) carrier_->carry_until(*encoder_, last_end_s_ - 1e-6, end_s_);
    if (generated_rate_ > 0) {
      const auto until = static_cast<std::int64_t>(std::llround(last_end_s_ * generated_rate_));
      if (until > audio_written_) {
        const auto samples = source_.generated_audio(audio_written_, static_cast<int>(until - audio_written_));
        encoder_->write_audio(samples.data(), static_cast<int>(samples.size()));
        audio_written_ = until;
      }
    }
  }
  void finish() override {
    // Audio ends with the video (what was converted), not with the source.
    if (carrier_) carrier_->carry_until(*encoder_, last_end_s_, last_end_s_);
    encoder_->finish();
  }

 private:
  StereoFrameSource& source_;
  std::optional<SourcePacketCarrier> carrier_;
  std::optional<VideoEncoder> encoder_;
  std::optional<double> end_s_;
  double last_end_s_ = 0.0;
  int generated_rate_ = 0;
  std::int64_t audio_written_ = 0;
};

// frames_%05d.png: one image per frame. Written files are removed again unless finish() is reached.
class ImageSequenceSink final : public FrameSink {
 public:
  ImageSequenceSink(const VideoConvertRequest& r) : pattern_(r.output), options_{r.encoder.overwrite, 8} {}
  ~ImageSequenceSink() override {
    if (finished_) return;
    std::error_code ec;
    for (const auto& f : written_) std::filesystem::remove(f, ec);
  }
  void write(const PackedFrame& frame) override {
    const std::string name = fmt::sprintf(pattern_, static_cast<int>(written_.size()) + 1);
    Image image(frame.width, frame.height);
    const std::size_t bpp = bytes_per_pixel(frame.bits);
    float* out = image.data();
    for (std::size_t i = 0; i < static_cast<std::size_t>(frame.width) * frame.height * 4; ++i) {
      if (bpp == 8) {
        std::uint16_t v;
        std::memcpy(&v, &frame.rgba[i * 2], 2);
        out[i] = v / 65535.f;
      } else {
        out[i] = frame.rgba[i] / 255.f;
      }
    }
    options_.bits = frame.bits > 8 ? 16 : 8;
    try {
      write_image_file(image, name, options_);
    } catch (const std::exception& e) {
      throw UserError(e.what(), 1);
    }
    written_.push_back(name);
  }
  void finish() override { finished_ = true; }

 private:
  std::string pattern_;
  ImageWriteOptions options_;
  std::vector<std::filesystem::path> written_;
  bool finished_ = false;
};

// Packed-frame buffers go back to the GL stage once encoded. A fresh 7.5 MB vector per frame,
// allocated on one thread and freed on another, came back from the kernel every time: zero-filled
// pages and a page fault each, ~10% of the CPU time of a conversion.
class BufferPool {
 public:
  std::vector<std::uint8_t> take(std::size_t size) {
    std::vector<std::uint8_t> buffer;
    {
      std::lock_guard lock(mutex_);
      if (!free_.empty()) {
        buffer = std::move(free_.back());
        free_.pop_back();
      }
    }
    buffer.resize(size);
    return buffer;
  }
  void give(std::vector<std::uint8_t> buffer) {
    std::lock_guard lock(mutex_);
    if (free_.size() < kKept) free_.push_back(std::move(buffer));
  }

 private:
  static constexpr std::size_t kKept = 8;  // more than the queue between the stages holds
  std::mutex mutex_;
  std::vector<std::vector<std::uint8_t>> free_;
};

// The GL stage: uploads each frame's views, renders both eyes straight into the packed frame and
// reads it back for the encoder.
class PackedFrameRenderer {
 public:
  PackedFrameRenderer(const VideoConvertRequest& r, int view_w, int view_h, int bits, std::array<int, 2> block)
      : compositor_(r.profile, r.compositor, std::make_shared<gl::EglContext>(gl::ContextOptions{r.compositor.gpu})),
        signal_(r.signal),
        view_w_(view_w),
        view_h_(view_h),
        bits_(bits),
        block_(block) {
    const auto panel = compositor_.panel();
    width_ = signal_.packed_width(panel[0]);
    height_ = signal_.packed_height(panel[1]);
    for (Eye eye : {Eye::left, Eye::right}) {
      const auto area = eye_area(signal_, eye, panel[0], panel[1]);
      if (!area) continue;
      if (panel[0] > area->width || panel[1] > area->height)
        throw UserError(fmt::format("the {}x{} panel of profile {} does not fit the {}x{} eye area of signal {}; "
                                    "use --signal sbs, tab, left or right",
                                    panel[0], panel[1], r.profile.name, area->width, area->height, signal_.name),
                        2);
      origins_[static_cast<int>(eye)] = {area->x + (area->width - panel[0]) / 2,
                                         area->y + (area->height - panel[1]) / 2};
    }
    const GLenum internal = bits > 8 ? GL_RGBA16 : GL_RGBA8;
    for (auto& t : views_) t = gl::make_texture_2d(internal, texture_w(), texture_h());
    packed_ = gl::make_texture_2d(internal, width_, height_);
    packed_fbo_ = gl::make_framebuffer(packed_);
  }
  int width() const { return width_; }
  int height() const { return height_; }

  PackedFrame render(const StereoVideoFrame& f, BufferPool& buffers) {
    const GLenum type = bits_ > 8 ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(views_[0].id(), 0, 0, 0, texture_w(), texture_h(), GL_RGBA, type, f.left.data());
    glTextureSubImage2D(views_[1].id(), 0, 0, 0, texture_w(), texture_h(), GL_RGBA, type, f.right.data());
    const float black[4] = {0.f, 0.f, 0.f, 1.f};
    glClearNamedFramebufferfv(packed_fbo_.id(), GL_COLOR, 0, black);
    for (Eye eye : {Eye::left, Eye::right}) {
      const auto& origin = origins_[static_cast<int>(eye)];
      if (!origin) continue;
      const GlTextureView view{views_[static_cast<int>(eye)].id(), view_w_, view_h_, f.aspect};
      const GlTarget target{packed_fbo_.id(), origin->first, origin->second};
      if (block_[0] > 1 || block_[1] > 1)
        compositor_.render_eye_reduced(eye, GlReducedView{view, block_}, target);
      else
        compositor_.render_eye(eye, view, target);
    }
    PackedFrame out{width_, height_, bits_ > 8 ? 16 : 8,
                    buffers.take(static_cast<std::size_t>(width_) * height_ * bytes_per_pixel(bits_)), f.pts_s};
    glBindFramebuffer(GL_READ_FRAMEBUFFER, packed_fbo_.id());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width_, height_, GL_RGBA, type, out.rgba.data());
    gl::check_error("reading back the packed frame");
    return out;
  }

 private:
  int texture_w() const { return view_w_ / block_[0]; }
  int texture_h() const { return view_h_ / block_[1]; }

  GlCompositor compositor_;
  Signal signal_;
  int view_w_, view_h_, bits_;
  std::array<int, 2> block_;
  int width_ = 0, height_ = 0;
  std::array<std::optional<std::pair<int, int>>, 2> origins_;
  std::array<gl::Texture, 2> views_;
  gl::Texture packed_;
  gl::Framebuffer packed_fbo_;
};

// Collects the first failure of any stage; the others stop when they see it.
class FirstError {
 public:
  void set(std::exception_ptr e) {
    std::lock_guard lock(mutex_);
    if (!error_) error_ = e;
    failed_ = true;
  }
  bool failed() const { return failed_.load(); }
  void rethrow() {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr error_;
  std::atomic<bool> failed_{false};
};

}  // namespace

bool is_image_sequence_pattern(const std::string& output) {
  static const std::regex pattern("%0?[0-9]*d");
  return std::regex_search(std::filesystem::path(output).filename().string(), pattern);
}

void convert_video(const VideoConvertRequest& r) {
  InterruptGuard guard;
  std::unique_ptr<StereoFrameSource> source;
  if (is_synthetic_spec(r.input)) {
    try {
      source = std::make_unique<SyntheticFrameSource>(r.input, r.start_s.value_or(0.0));
    } catch (const std::invalid_argument& e) {
      throw UserError(e.what(), 2);
    }
  } else {
    source = std::make_unique<FileFrameSource>(r);
  }

  // The first frame fixes the view size and depth for the whole run.
  auto first = source->next();
  if (!first) throw UserError(fmt::format("{}: no frames to convert", r.input), 1);
  const int view_w = first->width, view_h = first->height, bits = first->bits;
  const std::array<int, 2> block = first->block;

  std::optional<long> total = source->expected_frames();
  if (r.duration_s && total)
    total = std::min(*total, static_cast<long>(std::lround(*r.duration_s * source->frame_rate())));
  if (r.max_frames) total = total ? std::min(*total, *r.max_frames) : *r.max_frames;

  BoundedQueue<StereoVideoFrame> decoded(4);
  BoundedQueue<PackedFrame> packed(4);
  BufferPool buffers;
  FirstError error;
  std::atomic<long> frames_written{0};
  std::promise<std::pair<int, int>> size_promise;
  auto size_future = size_promise.get_future();

  // Decode thread: the source, limited by --frames / --duration.
  std::jthread decode([&] {
    try {
      long count = 0;
      std::optional<StereoVideoFrame> frame = std::move(first);
      while (frame && !interrupted && !error.failed()) {
        if (r.max_frames && count >= *r.max_frames) break;
        if (r.duration_s && frame->pts_s >= *r.duration_s - 1e-9) break;
        if (frame->width != view_w || frame->height != view_h || frame->bits != bits || frame->block != block)
          throw UserError(fmt::format("{}: the frame size changed mid-stream", r.input), 1);
        if (!decoded.push(std::move(*frame))) return;
        ++count;
        frame = source->next();
      }
      decoded.close();
    } catch (...) {
      error.set(std::current_exception());
      decoded.abort();
    }
  });

  // Composite thread: owns the GL context.
  std::jthread composite([&] {
    try {
      PackedFrameRenderer renderer(r, view_w, view_h, bits, block);
      size_promise.set_value({renderer.width(), renderer.height()});
      while (auto frame = decoded.pop()) {
        if (interrupted || error.failed()) break;
        if (!packed.push(renderer.render(*frame, buffers))) return;
      }
      packed.close();
    } catch (...) {
      error.set(std::current_exception());
      try {
        size_promise.set_exception(std::current_exception());
      } catch (const std::future_error&) {
      }
      decoded.abort();
      packed.abort();
    }
  });

  // Encode on this thread; polls for Ctrl-C while waiting.
  std::unique_ptr<FrameSink> sink;
  try {
    const auto [width, height] = size_future.get();
    if (is_image_sequence_pattern(r.output))
      sink = std::make_unique<ImageSequenceSink>(r);
    else
      sink = std::make_unique<EncodedFileSink>(r, *source, width, height, bits, source->origin_s());
    ProgressReporter progress(total, ProgressReporter::style_for(r.quiet));
    std::jthread watchdog([&](std::stop_token stop) {
      while (!stop.stop_requested()) {
        if (interrupted) {
          decoded.abort();
          packed.abort();
          return;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    });
    while (auto frame = packed.pop()) {
      sink->write(*frame);
      buffers.give(std::move(frame->rgba));
      ++frames_written;
      progress.frame_done();
    }
    watchdog.request_stop();
    watchdog.join();
    decode.join();
    composite.join();
    if (interrupted) throw UserError("interrupted: no output written", 130);
    error.rethrow();
    source->finish_checks(r.strict);
    sink->finish();
    progress.finish(fmt::format("wrote {}", r.output));
  } catch (...) {
    decoded.abort();
    packed.abort();
    if (decode.joinable()) decode.join();
    if (composite.joinable()) composite.join();
    sink.reset();  // removes what it had written
    if (interrupted) throw UserError("interrupted: no output written", 130);
    if (error.failed()) error.rethrow();
    throw;
  }
}

}  // namespace nelf::app
