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

#include "compositor/frame_compositor.hpp"
#include "compositor/gl/gl_compositor.hpp"
#include "core/bounded_queue.hpp"
#include "core/ffmpeg_raii.hpp"
#include "core/user_error.hpp"
#include "hmz_output/frame_sink.hpp"
#include "hmz_output/image_sink.hpp"
#include "hmz_output/packing.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/synthetic_source.hpp"
#include "inputs/video_source.hpp"
#include "inputs/view_regions.hpp"
#include "player/interrupt.hpp"
#include "player/progress.hpp"

namespace nelf {

namespace {

// An encoded video file, with the source's own streams copied when it has them (a file's audio,
// subtitles and chapters), else its decoded sound (the synthetic clip's tone) encoded.
class EncodedFileSink final : public FrameSink {
 public:
  EncodedFileSink(const VideoConvertRequest& r, std::unique_ptr<CarriedStreams> carried,
                  std::unique_ptr<AudioStream> audio, int width, int height, int bits, double frame_rate)
      : output_(r.output), frame_rate_(frame_rate), carried_(std::move(carried)), audio_(std::move(audio)) {
    EncoderSettings settings = r.encoder;
    settings.bits = bits;
    const AVRational rate = av_d2q(frame_rate, 100000);
    try {
      encoder_.emplace(r.output, width, height, rate.num, rate.den, settings, carried_ ? &carried_->layout() : nullptr);
    } catch (const std::invalid_argument& e) {
      throw UserError(e.what(), 2);
    } catch (const std::runtime_error& e) {
      throw UserError(e.what(), 1);
    }
    if (audio_) encoder_->add_audio_track(audio_->sample_rate(), audio_->channels());
    if (carried_) carried_indices_ = encoder_->carried_streams();
    end_s_ = r.duration_s;
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
       std::unique_ptr<CarriedStreams> carried;
       std::unique_ptr<AudioStream> audio;
       if (c.request.encoder.audio) {
         carried = c.source.open_carried_streams();
         if (!carried) audio = c.source.open_audio({}).stream;
       }
       return std::make_unique<EncodedFileSink>(c.request, std::move(carried), std::move(audio), c.width, c.height,
                                                c.bits, c.source.info().frame_rate);
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
      const PackedLayout layout = packed_layout(r.signal, r.profile.display.resolution);
      validate_fsaa(r.compositor.fsaa);
      require_eyes_fit(layout, r.profile.name, r.signal.name, "; use --signal sbs, tab, left or right");
      // On a software rasteriser 8-bit block means are composited on the CPU from tables recorded
      // once with the compositor's shaders; tables seen before come from the cache without GL.
      FrameCompositor compositor(r.profile, r.compositor, layout, nullptr, TableUse::any_views);
      compositor.prepare_views({view_w, view_h, bits, aspect, block});
      size_promise.set_value({layout.packed[0], layout.packed[1]});
      const std::size_t packed_bytes =
          static_cast<std::size_t>(layout.packed[0]) * layout.packed[1] * bytes_per_pixel(bits);
      while (auto frame = decoded.pop()) {
        if (interrupt_requested || error.failed()) break;
        const auto shared = std::make_shared<const StereoVideoFrame>(std::move(*frame));
        PackedFrame out{0, 0, 8, buffers.take(packed_bytes), 0.0};
        compositor.render(shared, {}, PackedTarget::bytes(out));
        if (!packed.push(std::move(out))) return;
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
