#include "player/convert_video.hpp"
#include "core/printable.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <exception>
#include <filesystem>
#include <future>
#include <mutex>
#include <thread>

extern "C" {
#include <libavformat/avformat.h>
#include <unistd.h>
}

#include "compositor/frame_compositor.hpp"
#include "compositor/gl/gl_compositor.hpp"
#include "compositor/overlays/subtitle_overlay.hpp"
#include "core/bounded_queue.hpp"
#include "core/ffmpeg_raii.hpp"
#include "core/user_error.hpp"
#include "hmz_output/file_sink_drivers.hpp"
#include "hmz_output/packing.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/synthetic_source.hpp"
#include "inputs/video_source.hpp"
#include "inputs/view_regions.hpp"
#include "player/depth_input.hpp"
#include "player/interrupt.hpp"
#include "player/progress.hpp"
#include "player/subtitle_choice.hpp"

namespace nelf {

namespace {

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

// The file sink the output name chooses, opened once the packed frame's size is known; the
// source's streams are opened only for a row that writes them.
std::unique_ptr<FrameSink> open_frame_sink(const VideoConvertRequest& r, Source& source, int width, int height,
                                           int bits) {
  const FileSinkDriver& driver = file_sink_driver_for(r.output);
  FrameSinkRequest request;
  request.output = r.output;
  request.width = width;
  request.height = height;
  request.bits = bits;
  request.frame_rate = source.info().frame_rate;
  request.encoder = r.encoder;
  request.duration_s = r.duration_s;
  if (driver.carries_streams && r.encoder.audio) {
    request.carried = source.open_carried_streams();
    if (!request.carried) request.audio = source.open_audio({}).stream;
  }
  request.refuse_as_output = [&inputs = r.inputs](const std::string& name) { inputs.refuse_as_output(name); };
  request.raw_fd = STDOUT_FILENO;
  return driver.open_file(std::move(request));
}

}  // namespace

void convert_video(const VideoConvertRequest& r) {
  InterruptGuard guard;
  SourceRequest request{r.input, r.right, r.layout, r.swap_eyes, r.start_s, r.quiet, r.allow_network, r.max_pixels};
  request.device_options = r.device_options;
  request.stop = &interrupt_requested;
  // Subtitles before the input (which says a line about itself), so that subtitles that cannot
  // be burned in are the only line said; an input that is not there is said as such first.
  std::error_code missing;
  const bool subtitles_first = r.burn_subs && (!r.burn_subs->file.empty() || std::filesystem::exists(r.input, missing));
  std::unique_ptr<SubtitleTrack> subtitles =
      subtitles_first ? choose_subtitles(r.input, r.burn_subs->file, r.start_s.value_or(0.0), true, r.quiet,
                                         r.burn_subs->stream, r.burn_subs->stereo)
                      : nullptr;
  std::unique_ptr<Source> source = open_source_for_depth(request, r.compositor.depth, r.profile);
  if (r.burn_subs && !subtitles)
    subtitles = choose_subtitles(r.input, r.burn_subs->file, r.start_s.value_or(0.0), true, r.quiet,
                                 r.burn_subs->stream, r.burn_subs->stereo);
  // Views arrive as the prefilter's block means when the input allows (render_eye_reduced); for an
  // 8-bit output a 10-bit source's means come dithered to 8 bits, which the CPU tables composite.
  const ViewGeometry view = source->info().view;
  source->negotiate({stereo_prefilter_block(r.profile, r.compositor, view.width, view.height, view.aspect),
                     r.encoder.bits > 8 ? 16 : 8});

  // The first frame fixes the view size and depth for the whole run.
  auto first = source->next();
  if (!first) throw UserError(fmt::format("{}: no frames to convert", r.input), 1);
  const int view_w = first->width, view_h = first->height, bits = first->bits;
  const double aspect = first->aspect;
  const std::array<int, 2> block = first->block;
  // A live input (a window) is recorded until --duration, --frames, its end or Ctrl-C: Ctrl-C ends
  // the recording with a complete file, as stopping a recording in OBS or ffmpeg does.
  const bool live = source->info().live;
  const auto stopping = [live] { return interrupt_requested && !live; };

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

  SubtitleDepthFollower sub_depth;  // the decode thread's (--sub-parallax auto)
  // Decode thread: the source, limited by --frames / --duration.
  std::jthread decode([&] {
    try {
      long count = 0;
      std::optional<StereoVideoFrame> frame = std::move(first);
      while (frame && !stopping() && !error.failed()) {
        if (r.max_frames && count >= *r.max_frames) break;
        if (r.duration_s && frame->pts_s >= *r.duration_s - 1e-9) break;
        if (frame->width != view_w || frame->height != view_h || frame->bits != bits || frame->block != block)
          throw UserError(fmt::format("{}: the frame size changed mid-stream", r.input), 1);
        if (subtitles) {
          const auto [w, h] = subtitle_canvas(*frame);
          const SubtitleBitmap subtitle = subtitles->render(frame->pts_s, w, h, frame->aspect);
          draw_subtitles(*frame, subtitle, sub_depth.parallax(*frame, subtitle, r.burn_subs->depth));
        }
        if (!decoded.push(std::move(*frame))) return;
        // Not one frame more than --frames is asked of the source: a live one may wait long for it.
        if (r.max_frames && ++count >= *r.max_frames) break;
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
        if (stopping() || error.failed()) break;
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
    sink = open_frame_sink(r, *source, width, height, bits);
    ProgressReporter progress(total, ProgressReporter::style_for(r.quiet));
    std::jthread watchdog([&](std::stop_token stop) {
      while (!stop.stop_requested()) {
        if (interrupt_requested && live) {
          source->interrupt();  // next() returns nothing more: the queued frames are written
          return;
        }
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
    if (stopping()) throw UserError("interrupted: no output written", 130);
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
