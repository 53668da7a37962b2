#include "player/convert_video.hpp"
#include "core/printable.hpp"

#include <fmt/format.h>
#include <fmt/printf.h>
#include <algorithm>
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
#include <unistd.h>
}

#include "compositor/cpu/composite_table_cache.hpp"
#include "compositor/gl/gl_compositor.hpp"
#include "core/bounded_queue.hpp"
#include "core/ffmpeg_raii.hpp"
#include "core/gl/egl_context.hpp"
#include "core/user_error.hpp"
#include "hmz_output/frame_sink.hpp"
#include "hmz_output/image_sink.hpp"
#include "hmz_output/packing.hpp"
#include "inputs/ffmpeg_input.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/synthetic_source.hpp"
#include "inputs/video_source.hpp"
#include "inputs/view_regions.hpp"
#include "player/interrupt.hpp"
#include "player/progress.hpp"

namespace nelf {

namespace {

// Carries the source's audio and subtitles: a second demuxer on the same file, read in step with
// the video so the muxer's interleaving buffer stays small.
class SourcePacketCarrier {
 public:
  SourcePacketCarrier(const std::string& path, double origin_s, bool allow_network) : origin_s_(origin_s) {
    network_.allow_network = allow_network;
    const int opened = ffmpeg::open_input(format_, path, network_);
    if (const auto stopped = ffmpeg::guard_stop(path, network_)) throw UserError(*stopped, 1);
    if (opened < 0)
      throw UserError(fmt::format("{}: cannot reopen for audio: {}", path, ffmpeg::error_string(opened)), 1);
    const int found = ffmpeg::find_stream_info(format_.get(), network_);
    if (const auto stopped = ffmpeg::guard_stop(path, network_)) throw UserError(*stopped, 1);
    if (found < 0) throw UserError(fmt::format("{}: cannot read stream information", path), 1);
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
      const bool wanted = std::find(carried.begin(), carried.end(), packet_->stream_index) != carried.end();
      // Only a carried packet waits for later: in MPEG-TS the audio lies behind the video in the
      // file (the muxer gathers several audio frames per PES packet), so stopping at a video
      // packet would leave out audio that belongs before it.
      if (wanted && until_s && t > *until_s) return;  // keep it for later
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
  ffmpeg::InputGuard network_;  // before `format_`: the context points at it while it lives
  ffmpeg::FormatContextPtr format_;
  ffmpeg::PacketPtr packet_;
  double origin_s_;
  bool done_ = false;
};

class EncodedFileSink final : public FrameSink {
 public:
  EncodedFileSink(const VideoConvertRequest& r, Source& source, int width, int height, int bits, double origin_s)
      : source_(source), output_(r.output) {
    if (!source.audio_path().empty() && r.encoder.audio)
      carrier_.emplace(source.audio_path(), origin_s, r.allow_network);
    EncoderSettings settings = r.encoder;
    settings.bits = bits;
    const AVRational rate = av_d2q(source.info().frame_rate, 100000);
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
    last_end_s_ = frame.pts_seconds + 1.0 / source_.info().frame_rate;
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
  std::string description() const override { return output_; }

 private:
  Source& source_;
  std::string output_;
  std::optional<SourcePacketCarrier> carrier_;
  std::optional<VideoEncoder> encoder_;
  std::optional<double> end_s_;
  double last_end_s_ = 0.0;
  int generated_rate_ = 0;
  std::int64_t audio_written_ = 0;
};

// frames_%05d.png: one image per frame. Written files are removed again unless finish() is reached.
// A plain image name (x.png) holds the one frame converted, written only by finish(): the file
// appears when the conversion succeeded, or not at all.
class ImageSequenceSink final : public FrameSink {
 public:
  ImageSequenceSink(const VideoConvertRequest& r)
      : pattern_(r.output),
        inputs_(r.inputs),
        single_(!is_image_sequence_pattern(r.output)),
        options_{r.encoder.overwrite, 8} {}
  ~ImageSequenceSink() override {
    if (finished_) return;
    std::error_code ec;
    for (const auto& f : written_) std::filesystem::remove(f, ec);
  }
  void write(const PackedFrame& frame) override {
    if (single_) {
      if (single_frame_) throw std::logic_error("a single image output was given a second frame");
      single_frame_.emplace(frame);
      return;
    }
    write_frame(frame, fmt::sprintf(pattern_, static_cast<int>(written_.size()) + 1));
  }
  void finish() override {
    if (single_ && single_frame_) write_frame(*single_frame_, pattern_);
    finished_ = true;
  }
  std::string description() const override { return pattern_; }

 private:
  void write_frame(const PackedFrame& frame, const std::string& name) {
    // Any frame's name may be an input (out_%05d.png expanding to an input's name, or a link to it).
    inputs_.refuse_as_output(name);
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

  std::string pattern_;
  const InputFiles& inputs_;
  bool single_;
  std::optional<PackedFrame> single_frame_;
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

// The compositing stage: both eyes of each frame into a packed frame for the encoder, from CPU
// composite tables on software GL (see below), else with GL (upload the views, render straight
// into the packed frame, read it back).
class PackedFrameRenderer {
 public:
  PackedFrameRenderer(const VideoConvertRequest& r, int view_w, int view_h, int bits, double aspect,
                      std::array<int, 2> block)
      : signal_(r.signal), view_w_(view_w), view_h_(view_h), bits_(bits), block_(block) {
    validate_fsaa(r.compositor.fsaa);
    const auto panel = panel_ = r.profile.display.resolution;
    const PackedLayout layout = packed_layout(signal_, panel);
    width_ = layout.packed[0];
    height_ = layout.packed[1];
    for (const auto& area : layout.areas)
      if (area && (panel[0] > area->width || panel[1] > area->height))
        throw UserError(fmt::format("the {}x{} panel of profile {} does not fit the {}x{} eye area of signal {}; "
                                    "use --signal sbs, tab, left or right",
                                    panel[0], panel[1], r.profile.name, area->width, area->height, signal_.name),
                        2);
    origins_ = layout.origins;
    // On a software rasteriser 8-bit block means are composited on the CPU from tables recorded
    // once with the compositor's shaders (compositor/cpu/composite_table.hpp): several times cheaper
    // than llvmpipe's passes. Tables seen before come from the cache without starting GL at all.
    const CompositeTableCache cache;
    if (bits == 8 && tables_from_cache(r, cache, aspect)) return;
    compositor_.emplace(r.profile, r.compositor,
                        std::make_shared<gl::EglContext>(gl::ContextOptions{r.compositor.gpu}));
    if (bits == 8 && prefer_composite_table(compositor_->context())) load_tables(r, cache, &*compositor_, aspect);
    if (tables_[0] || tables_[1]) return;
    const GLenum internal = bits > 8 ? GL_RGBA16 : GL_RGBA8;
    for (auto& t : views_) t = gl::make_texture_2d(internal, texture_w(), texture_h());
    packed_ = gl::make_texture_2d(internal, width_, height_);
    packed_fbo_ = gl::make_framebuffer(packed_);
  }
  int width() const { return width_; }
  int height() const { return height_; }

  PackedFrame render(const StereoVideoFrame& f, BufferPool& buffers) {
    if (tables_[0] || tables_[1]) return render_from_tables(f, buffers);
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
        compositor_->render_eye_reduced(eye, GlReducedView{view, block_}, target);
      else
        compositor_->render_eye(eye, view, target);
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
  // Both eyes' tables from `cache`, where the CPU path is wanted without asking GL: never on a
  // machine that may have a GPU (a render node), unless NELF_COMPOSITE=table says so.
  bool tables_from_cache(const VideoConvertRequest& r, const CompositeTableCache& cache, double aspect) {
    const CompositeChoice choice = composite_choice();
    if (choice == CompositeChoice::gl || (choice == CompositeChoice::automatic && has_render_node())) return false;
    // GL would have refused a --gpu (or NELF_GPU) that names no device: so does a cache hit.
    gl::check_requested_gpu(gl::ContextOptions{r.compositor.gpu});
    return load_tables(r, cache, nullptr, aspect);
  }
  // Both eyes' tables from `cache`, else recorded with `recorder` (when given, and kept in
  // `cache`); none when an eye has no table (fsaa other than 1, whole views).
  bool load_tables(const VideoConvertRequest& r, const CompositeTableCache& cache, GlCompositor* recorder,
                   double aspect) {
    for (Eye eye : {Eye::left, Eye::right}) {
      if (!origins_[static_cast<int>(eye)]) continue;
      tables_[static_cast<int>(eye)] = load_or_record_composite_table(cache, recorder, r.profile, r.compositor, eye,
                                                                      view_w_, view_h_, aspect, block_);
      if (!tables_[static_cast<int>(eye)]) {
        tables_ = {};
        return false;
      }
    }
    return tables_[0] || tables_[1];
  }

  // The CPU path: both eyes from their tables straight into the packed frame, black around them.
  PackedFrame render_from_tables(const StereoVideoFrame& f, BufferPool& buffers) {
    PackedFrame out{width_, height_, 8, buffers.take(static_cast<std::size_t>(width_) * height_ * 4), f.pts_s};
    fill_outside_eyes(out.rgba.data());
    // While x264 fills its look-ahead the compositing is what the pipeline waits for: the eyes
    // render in parallel.
    render_packed_eyes(tables_, {f.left.data(), f.right.data()}, static_cast<std::size_t>(texture_w()) * 4, origins_,
                       out.rgba.data(), static_cast<std::size_t>(width_) * 4);
    return out;
  }
  // Opaque black wherever the eyes do not draw (the gap, and borders when a panel is smaller than
  // its eye area); the eyes overwrite all of their own pixels.
  void fill_outside_eyes(std::uint8_t* rgba) const {
    const auto panel = panel_;
    const auto fill = [&](int y, int from, int to) {
      if (from < to)
        fill_opaque_black(
            {rgba + (static_cast<std::size_t>(y) * width_ + from) * 4, static_cast<std::size_t>(to - from) * 4});
    };
    for (int y = 0; y < height_; ++y) {
      int from = 0;
      for (const auto& origin : origins_) {
        if (!origin || y < origin->second || y >= origin->second + panel[1]) continue;
        fill(y, from, origin->first);
        from = origin->first + panel[0];
      }
      fill(y, from, width_);
    }
  }

  int texture_w() const { return view_w_ / block_[0]; }
  int texture_h() const { return view_h_ / block_[1]; }

  std::optional<GlCompositor> compositor_;  // none when the tables came from the cache
  Signal signal_;
  std::array<int, 2> panel_{0, 0};
  int view_w_, view_h_, bits_;
  std::array<int, 2> block_;
  int width_ = 0, height_ = 0;
  std::array<std::optional<std::pair<int, int>>, 2> origins_;
  std::array<std::optional<CompositeTable>, 2> tables_;  // per eye, the CPU path
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

// What a sink is opened with, once the packed frame's size is known.
struct FrameSinkContext {
  const VideoConvertRequest& request;
  Source& source;
  int width, height, bits;
};

// The outputs of `nelf convert` for video, chosen by the output name: the first row whose test
// accepts it. A new kind of output is its sink plus one row.
struct FrameSinkDriver {
  std::string_view name;
  bool (*accepts)(const std::string& output);
  std::unique_ptr<FrameSink> (*open)(const FrameSinkContext& context);
};

constexpr FrameSinkDriver kFrameSinks[] = {
    {"raw", is_raw_output,
     [](const FrameSinkContext& c) {
       return open_raw_frame_sink(STDOUT_FILENO, c.width, c.height, c.source.info().frame_rate);
     }},
    {"image", [](const std::string& o) { return is_image_sequence_pattern(o) || is_image_file_name(o); },
     [](const FrameSinkContext& c) -> std::unique_ptr<FrameSink> {
       return std::make_unique<ImageSequenceSink>(c.request);
     }},
    {"encoded", [](const std::string&) { return true; },
     [](const FrameSinkContext& c) -> std::unique_ptr<FrameSink> {
       return std::make_unique<EncodedFileSink>(c.request, c.source, c.width, c.height, c.bits, c.source.origin_s());
     }},
};

std::unique_ptr<FrameSink> open_frame_sink(const FrameSinkContext& context) {
  for (const FrameSinkDriver& driver : kFrameSinks)
    if (driver.accepts(context.request.output)) return driver.open(context);
  throw std::logic_error("no frame sink accepts " + context.request.output);
}

}  // namespace

bool is_raw_output(const std::string& output) { return output == "-"; }

bool is_image_sequence_pattern(const std::string& output) {
  static const std::regex pattern("%0?[0-9]*d");
  return std::regex_search(std::filesystem::path(output).filename().string(), pattern);
}

void convert_video(const VideoConvertRequest& r) {
  InterruptGuard guard;
  std::unique_ptr<Source> source = open_source(
      SourceRequest{r.input, r.right, r.layout, r.swap_eyes, r.start_s, r.quiet, r.allow_network, r.max_pixels});
  // Views arrive as the prefilter's block means when the input allows (render_eye_reduced).
  const ViewGeometry view = source->info().view;
  source->negotiate({stereo_prefilter_block(r.profile, r.compositor, view.width, view.height, view.aspect)});

  // The first frame fixes the view size and depth for the whole run.
  auto first = source->next();
  if (!first) throw UserError(fmt::format("{}: no frames to convert", r.input), 1);
  const int view_w = first->width, view_h = first->height, bits = first->bits;
  const double aspect = first->aspect;
  const std::array<int, 2> block = first->block;

  std::optional<long> total = source->info().expected_frames;
  if (r.duration_s && total)
    total = std::min(*total, static_cast<long>(std::lround(*r.duration_s * source->info().frame_rate)));
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
      while (frame && !interrupt_requested && !error.failed()) {
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
      PackedFrameRenderer renderer(r, view_w, view_h, bits, aspect, block);
      size_promise.set_value({renderer.width(), renderer.height()});
      while (auto frame = decoded.pop()) {
        if (interrupt_requested || error.failed()) break;
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
    sink = open_frame_sink({r, *source, width, height, bits});
    ProgressReporter progress(total, ProgressReporter::style_for(r.quiet));
    std::jthread watchdog([&](std::stop_token stop) {
      while (!stop.stop_requested()) {
        if (interrupt_requested) {
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
    if (interrupt_requested) throw UserError("interrupted: no output written", 130);
    error.rethrow();
    if (const std::int64_t lost = source->lost_frames(); lost > 0) {
      const std::string what = fmt::format("{}: damaged or truncated: {} frame(s) lost or damaged", r.input, lost);
      if (r.strict) throw UserError(what + " (--strict)", 1);
      fmt::print(stderr, "nelf: warning: {}; converted what decodes\n", printable(what));
    }
    sink->finish();
    progress.finish(fmt::format("wrote {}", sink->description()));
  } catch (...) {
    decoded.abort();
    packed.abort();
    if (decode.joinable()) decode.join();
    if (composite.joinable()) composite.join();
    sink.reset();  // removes what it had written
    if (interrupt_requested) throw UserError("interrupted: no output written", 130);
    if (error.failed()) error.rethrow();
    throw;
  }
}

}  // namespace nelf
