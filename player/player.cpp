#include "player/player.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "compositor/cpu/composite_ahead.hpp"
#include "compositor/cpu/composite_table_cache.hpp"
#include "compositor/gl/gl_compositor.hpp"
#include "compositor/overlays/calibration_overlay.hpp"
#include "compositor/overlays/text_overlay.hpp"
#include "core/gl/objects.hpp"
#include "core/image_library.hpp"
#include "core/user_error.hpp"
#include "hmz_output/audio_output.hpp"
#include "hmz_output/packing.hpp"
#include "inputs/audio_source.hpp"
#include "inputs/test_patterns.hpp"
#include "player/audio_feeder.hpp"
#include "player/frame_log.hpp"
#include "player/frame_queue.hpp"
#include "player/key_bindings.hpp"
#include "player/packed_renderer.hpp"

namespace nelf {

namespace {

using Steady = std::chrono::steady_clock;
double seconds_since(Steady::time_point t) { return std::chrono::duration<double>(Steady::now() - t).count(); }

using playback::AudioFeeder;
using playback::decode_loop;
using playback::FrameLog;
using playback::FrameQueue;
using playback::PackedRenderer;

}  // namespace

std::string play_summary(const PlayResult& r) {
  std::string line = fmt::format("{} frames shown, {} repeated, {} dropped", r.counters.shown, r.counters.repeated,
                                 r.counters.dropped);
  if (r.video_decode_errors > 0) line += fmt::format(", {} video frames lost to decode errors", r.video_decode_errors);
  if (r.audio_decode_errors > 0) line += fmt::format(", {} audio decode errors", r.audio_decode_errors);
  return line;
}

PlayResult play(Display& display, StereoFrameSource& source, const PlayerOptions& options,
                const std::atomic<bool>* stop) {
  PlayResult result;
  // The on-screen messages draw their text with OpenImageIO, loaded on first use: load it now
  // (~0.3 s) rather than as a hitch at the first key press. Without it the film still plays; the
  // first message then stops play with the same error, as a missing font would.
  try {
    image_library::preload();
  } catch (const image_library::ImageLibraryError& e) {
    std::fprintf(stderr, "nelf: warning: %s\n", e.what());
  }
  display.context()->make_current();
  PackedRenderer renderer(display, options);
  FrameLog log(options.log_frames);

  // The master clock: the sound's when there is sound.
  std::unique_ptr<AudioOutput> audio;
  std::unique_ptr<AudioFeeder> feeder;
  SystemClock system_clock;
  PlaybackClock* clock = &system_clock;
  if (!options.audio) {
    result.sound = "--no-audio";
  } else if (source.has_generated_audio()) {
    result.sound = "the synthetic clip's tone is not played";
  } else if (source.audio_path().empty()) {
    result.sound = "no audio stream";
  } else {
    std::optional<AudioSource> audio_source;
    try {
      audio_source.emplace(source.audio_path(),
                           AudioSourceOptions{options.audio_rate, source.origin_s(), options.allow_network});
    } catch (const AudioError& e) {
      result.sound = std::string(e.what()).find("no audio stream") != std::string::npos
                         ? "no audio stream"
                         : fmt::format("the audio cannot be decoded ({})", e.what());
    }
    if (audio_source) {
      std::string why_not;
      audio = AudioOutput::open(audio_source->sample_rate(), why_not);
      if (!audio) {
        result.sound = fmt::format("no audio device ({})", why_not);
      } else {
        // The device may run at another rate: decode for the rate it has.
        if (audio->sample_rate() != audio_source->sample_rate())
          audio_source.emplace(source.audio_path(),
                               AudioSourceOptions{audio->sample_rate(), source.origin_s(), options.allow_network});
        result.had_sound = true;
        result.sound = audio->description();
        clock = audio.get();
        feeder = std::make_unique<AudioFeeder>(std::move(*audio_source), *audio);
      }
    }
  }
  if (!options.quiet) {
    if (result.had_sound)
      std::fprintf(stderr, "nelf: sound: %s\n", result.sound.c_str());
    else
      std::fprintf(stderr, "nelf: %s: playing without sound\n", result.sound.c_str());
  }
  clock->set_paused(true);  // starts with the first frame on screen

  const double refresh_period = 1.0 / display.refresh_hz();
  const double fps = source.frame_rate();
  FrameScheduler scheduler(refresh_period, fps > 0 ? 1.0 / fps : 0.0);
  // Views as the prefilter's block means where the input allows (swscale makes them while
  // converting from YUV): far less to convert, upload and composite per frame.
  const auto blocks_for = [&options](const Profile& profile) -> ViewBlockChooser {
    return [profile, compositor = options.compositor](int width, int height, double aspect) {
      return stereo_prefilter_block(profile, compositor, width, height, aspect);
    };
  };
  source.reduce_views(blocks_for(options.profile));
  constexpr std::size_t queue_capacity = 6;
  FrameQueue queue(queue_capacity);
  std::jthread decoder([&] { decode_loop(source, queue); });
  struct StopDecoder {
    FrameQueue& queue;
    ~StopDecoder() { queue.stop(); }
  } stop_decoder{queue};

  const auto duration = source.duration_s();

  bool paused = false, started = false, calibration = false, swap_eyes = false, dirty = false;
  std::size_t help_line = 0;  // the next line of the key help that h shows
  bool awaiting_seek = false;
  bool show_while_paused = false;  // a seek while paused shows the first frame at the new place
  std::shared_ptr<const StereoVideoFrame> current;
  std::string message;
  Steady::time_point message_until{};
  // Time from the decision to the end of present(): the median of the last few renders (the first,
  // which compiles shaders, does not count), so one slow frame on a loaded machine does not make
  // the next ones come early.
  std::deque<double> render_times;
  double render_s = refresh_period;
  std::int64_t refresh = 0;
  auto next_tick = Steady::now();

  auto say = [&](std::string text) {
    dirty = true;
    if (!options.on_screen_messages) return;
    message = std::move(text);
    renderer.set_message(message);
    message_until = Steady::now() + std::chrono::seconds(2);
  };
  auto seek_by = [&](double delta) {
    const double from = current ? current->pts_s : clock->now();
    double target = std::max(0.0, from + delta);
    if (duration) target = std::min(target, std::max(0.0, *duration - 0.001));
    queue.seek(target);
    if (feeder) feeder->seek(target);
    clock->restart_at(target);
    clock->set_paused(true);  // until the first frame after the seek is decoded
    awaiting_seek = true;
    scheduler.reset();
    say(fmt::format("{} {:.0f} s: {}:{:02d}", delta < 0 ? "back" : "forward", std::abs(delta),
                    static_cast<int>(target) / 60, static_cast<int>(target) % 60));
  };
  auto change_profile = [&](Profile changed, const std::string& what) {
    try {
      renderer.set_profile(changed);
      queue.reduce_views(blocks_for(changed));  // the block follows the optics
      dirty = true;
      say(what);
    } catch (const std::exception& e) {
      say(fmt::format("cannot: {}", e.what()));
    }
  };

  // Before the clock starts (after the first frame) or restarts (after a seek): the next frames
  // composited ahead, waiting up to 0.3 s. The worker's first frames take 40 ms and more (new
  // buffers, cold caches), and with the clock running the first refreshes dropped frames waiting
  // for them (2 of 300 at 30 fps in a run of tests/bench/play_pacing.sh).
  auto prime_ahead = [&] {
    const std::vector<FrameQueue::Frame> next = queue.front(queue_capacity);
    renderer.composite_ahead(swap_eyes, next);
    renderer.wait_for_ahead(std::chrono::milliseconds(300));
  };

  // Wait (briefly) for the first frame so the clock does not run ahead of a slow start.
  while (!queue.wait_for_frame(std::chrono::milliseconds(50))) {
    bool end = false;
    queue.snapshot(end);
    if (end || (stop && stop->load()) || display.close_requested()) break;
    display.poll_events();
  }

  for (;;) {
    for (const KeyPress& key : display.poll_events()) {
      const std::optional<Command> command = command_for(KeyScope::play, key);
      if (!command) continue;
      switch (*command) {
        case Command::quit:
          result.end = PlayEnd::quit_key;
          break;
        case Command::pause:
          paused = !paused;
          if (!awaiting_seek && started) clock->set_paused(paused);
          say(paused ? "paused" : "playing");
          break;
        case Command::seek_back_10s:
          seek_by(-10);
          break;
        case Command::seek_forward_10s:
          seek_by(10);
          break;
        case Command::seek_forward_60s:
          seek_by(60);
          break;
        case Command::seek_back_60s:
          seek_by(-60);
          break;
        case Command::screen_farther:
        case Command::screen_nearer: {
          Profile p = renderer.profile();
          const double now_mm = p.screen.distance_mm > 0 ? p.screen.distance_mm : p.viewing.virtual_image_mm;
          p.screen.distance_mm = *command == Command::screen_nearer ? now_mm / 1.25 : now_mm * 1.25;
          change_profile(p, fmt::format("screen distance {:.0f} mm", p.screen.distance_mm));
          break;
        }
        case Command::ipd_narrower:
        case Command::ipd_wider: {
          Profile p = renderer.profile();
          p.viewing.ipd_mm += *command == Command::ipd_narrower ? -0.5 : 0.5;
          change_profile(p, fmt::format("IPD {:.1f} mm", p.viewing.ipd_mm));
          break;
        }
        case Command::swap_eyes:
          swap_eyes = !swap_eyes;
          dirty = true;
          say(swap_eyes ? "eyes swapped" : "eyes as the source says");
          break;
        case Command::calibration_grid:
          calibration = !calibration;
          try {
            if (current) renderer.upload(current, calibration);
          } catch (const TestPatternError& e) {
            calibration = false;
            if (current) renderer.upload(current, calibration);
            say(fmt::format("no calibration grid: {}", e.what()));
            break;
          }
          dirty = true;
          say(calibration ? "calibration grid on" : "calibration grid off");
          break;
        case Command::fullscreen:
          say(display.toggle_fullscreen());
          dirty = true;
          break;
        case Command::help: {
          // Each press shows the next line on screen; the first also prints them all.
          const std::vector<std::string> lines = key_help(KeyScope::play);
          if (help_line == 0 && !options.quiet)
            for (const std::string& line : lines) fmt::print(stderr, "nelf: key {}\n", line);
          say(lines[help_line++ % lines.size()]);
          dirty = true;
          break;
        }
        default:
          break;  // a calibrate command: not bound in play
      }
    }
    if (result.end == PlayEnd::quit_key) break;
    if (display.close_requested()) {
      result.end = PlayEnd::window_closed;
      break;
    }
    if (stop && stop->load()) {
      result.end = PlayEnd::interrupted;
      break;
    }

    const auto decided_at = Steady::now();
    const char* event = nullptr;
    double upload_s = 0.0, render_only_s = 0.0, present_s = 0.0;
    bool end = false;
    std::vector<double> queued = queue.snapshot(end);
    if (awaiting_seek && (!queued.empty() || end)) {
      awaiting_seek = false;
      show_while_paused = paused;
      if (!paused) {
        prime_ahead();
        clock->set_paused(false);
      }
    }
    bool finished = false;
    if (!awaiting_seek && (!(paused && started) || show_while_paused)) {
      // When this refresh will be seen: after the next vblank, or once rendered and presented.
      double visible_at = clock->now() + (display.vsync() ? refresh_period : render_s);
      // The clock waits, paused, for the first frame to be on screen; a stream whose video starts
      // later than its sound (mkv: video at 0.023 s, audio at 0) would wait for it for ever. The
      // first frame is the poster shown while the clock waits, whenever its pts.
      if (!started && !queued.empty()) visible_at = std::max(visible_at, queued.front());
      const FrameDecision d = scheduler.decide(visible_at, queued, end);
      if (d.drop > 0 || d.show_front) {
        auto frame = queue.pop(d.drop, d.show_front);
        if (frame) {
          show_while_paused = false;
          current = std::move(frame);
          const auto t = Steady::now();
          renderer.upload(current, calibration);
          if (log.enabled()) glFinish();  // so that the log says where the time goes
          upload_s = seconds_since(t);
          dirty = true;
          event = "shown";
        }
      }
      if (d.repeat) event = "repeated";
      finished = d.finished;
    }
    if (!message.empty() && Steady::now() > message_until) {
      message.clear();
      renderer.set_message("");
      dirty = true;
    }
    if (finished) break;

    bool ahead = false;
    if (dirty) {
      auto t = Steady::now();
      ahead = renderer.render(swap_eyes);
      if (ahead) ++result.composited_ahead;
      if (log.enabled()) glFinish();
      render_only_s = seconds_since(t);
      if (options.after_render) options.after_render(display, current ? current->pts_s : 0.0);
      t = Steady::now();
      try {
        display.present();
      } catch (const std::runtime_error& e) {
        throw UserError(fmt::format("the display was lost: {}", e.what()), 1);
      }
      present_s = seconds_since(t);
      dirty = false;
      if (started) {
        render_times.push_back(seconds_since(decided_at));
        if (render_times.size() > 9) render_times.pop_front();
        std::vector<double> sorted(render_times.begin(), render_times.end());
        std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
        render_s = sorted[sorted.size() / 2];
      }
      if (!started) {
        started = true;
        if (!paused && !awaiting_seek) {
          prime_ahead();
          clock->set_paused(false);
        }
      }
      if (!event) event = "redrawn";
    } else if (display.vsync()) {
      display.present();  // paces the loop at the refresh
    }
    if (event)
      log.write(refresh, event, current ? std::optional(current->pts_s) : std::nullopt, clock->now(),
                audio ? std::optional(audio->now()) : std::nullopt, scheduler.counters(), upload_s, render_only_s,
                present_s, queued.size(), ahead);
    ++refresh;

    // The next frames, composited on the worker while this thread waits for the next refresh; not
    // those whose time will have passed by then (the next refresh drops them): after a slow spell
    // the worker would otherwise spend itself on frames never shown.
    {
      const std::vector<FrameQueue::Frame> next = queue.front(queue_capacity);
      std::vector<double> next_pts;
      for (const auto& f : next) next_pts.push_back(f->pts_s);
      const double next_visible = clock->now() + refresh_period + (display.vsync() ? refresh_period : render_s);
      const std::size_t stale = scheduler.stale(next_visible, next_pts);
      renderer.composite_ahead(swap_eyes, std::span(next).subspan(stale));
    }

    if (!display.vsync()) {
      next_tick += std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(refresh_period));
      const auto now = Steady::now();
      if (next_tick < now - std::chrono::milliseconds(100)) next_tick = now;  // far behind: do not race
      std::this_thread::sleep_until(next_tick);
    }
  }

  queue.stop();
  decoder.join();
  if (feeder) result.audio_decode_errors = feeder->decode_errors();
  feeder.reset();
  result.counters = scheduler.counters();
  result.video_decode_errors = source.lost_frames();
  return result;
}

}  // namespace nelf
