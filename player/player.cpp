#include "player/player.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "compositor/frame_compositor.hpp"
#include "core/image_library.hpp"
#include "core/user_error.hpp"
#include "hmz_output/audio_output.hpp"
#include "hmz_output/packing.hpp"
#include "player/frame_log.hpp"
#include "player/frame_queue.hpp"
#include "player/key_bindings.hpp"
#include "player/play_commands.hpp"
#include "player/play_sound.hpp"
#include "player/refresh_pacing.hpp"

namespace nelf {

namespace {

using Steady = std::chrono::steady_clock;
double seconds_since(Steady::time_point t) { return std::chrono::duration<double>(Steady::now() - t).count(); }

using playback::decode_loop;
using playback::FrameLog;
using playback::FrameQueue;
using playback::PlayCommands;
using playback::PlaySound;
using playback::PlayState;
using playback::RefreshTicker;
using playback::RenderTime;

}  // namespace

std::string play_summary(const PlayResult& r) {
  std::string line = fmt::format("{} frames shown, {} repeated, {} dropped", r.counters.shown, r.counters.repeated,
                                 r.counters.dropped);
  if (r.video_decode_errors > 0) line += fmt::format(", {} video frames lost to decode errors", r.video_decode_errors);
  if (r.audio_decode_errors > 0) line += fmt::format(", {} audio decode errors", r.audio_decode_errors);
  return line;
}

PlayResult play(Display& display, Source& source, const PlayerOptions& options, const std::atomic<bool>* stop) {
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
  const PackedLayout layout = packed_layout(options.signal, options.profile.display.resolution);
  FrameCompositor compositor(options.profile, options.compositor, layout, display.context());
  require_eyes_fit(layout, options.profile.name, options.signal.name);
  const std::array<int, 2> packed = display.packed_size();
  for (const auto& origin : layout.origins)
    if (origin && (origin->first + layout.eye[0] > packed[0] || origin->second + layout.eye[1] > packed[1]))
      throw UserError(fmt::format("the display's {}x{} frame is smaller than signal {} needs", packed[0], packed[1],
                                  options.signal.name),
                      1);
  compositor.set_grid_pattern(playback::calibration_grid_pattern());
  const GlPackedTarget target{display.packed_framebuffer(), display.packed_texture(), packed};
  FrameLog log(options.log_frames);

  // The master clock: the sound's when there is sound. It starts with the first frame on screen.
  PlaySound sound(source, options);
  result.had_sound = sound.playing();
  result.sound = sound.description();
  if (!options.quiet)
    std::fprintf(stderr, result.had_sound ? "nelf: sound: %s\n" : "nelf: %s: playing without sound\n",
                 result.sound.c_str());
  PlaybackClock& clock = sound.clock();
  clock.set_paused(true);

  const double refresh_period = 1.0 / display.refresh_hz();
  const SourceInfo info = source.info();
  const double fps = info.frame_rate;
  FrameScheduler scheduler(refresh_period, fps > 0 ? 1.0 / fps : 0.0);
  source.negotiate(compositor.wanted_view_format(info.view));
  constexpr std::size_t queue_capacity = 6;
  FrameQueue queue(queue_capacity);
  std::jthread decoder([&] { decode_loop(source, queue); });
  struct StopDecoder {
    FrameQueue& queue;
    ~StopDecoder() { queue.stop(); }
  } stop_decoder{queue};

  PlayState state;
  PlayCommands commands(state, display, compositor, queue, sound, scheduler, options, info.duration_s, info.view);
  RenderTime render_time(refresh_period);  // the first render, which compiles shaders, does not count
  RefreshTicker ticker(refresh_period);
  std::int64_t refresh = 0;
  // When a refresh starting now will be seen: after the next vblank, or once rendered and presented.
  const auto seen_after = [&] { return display.vsync() ? refresh_period : render_time.median_s(); };

  // Before the clock starts (after the first frame) or restarts (after a seek): the next frames
  // composited ahead, waiting up to 0.3 s. The worker's first frames take 40 ms and more (new
  // buffers, cold caches), and with the clock running the first refreshes dropped frames waiting
  // for them (2 of 300 at 30 fps in a run of tests/bench/play_pacing.sh).
  const auto start_clock = [&] {
    compositor.composite_ahead(queue.front(queue_capacity), commands.overlays(), target);
    compositor.wait_for_ahead(std::chrono::milliseconds(300));
    clock.set_paused(false);
  };

  // Wait (briefly) for the first frame so the clock does not run ahead of a slow start.
  while (!queue.wait_for_frame(std::chrono::milliseconds(50))) {
    bool end = false;
    queue.snapshot(end);
    if (end || (stop && stop->load()) || display.close_requested()) break;
    display.poll_events();
  }

  for (;;) {
    bool quit = false;
    for (const KeyPress& key : display.poll_events())
      if (const std::optional<Command> command = command_for(KeyScope::play, key))
        if (!commands.apply(*command)) quit = true;
    if (quit) {
      result.end = PlayEnd::quit_key;
      break;
    }
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
    if (state.awaiting_seek && (!queued.empty() || end)) {
      state.awaiting_seek = false;
      state.show_while_paused = state.paused;
      if (!state.paused) start_clock();
    }
    bool finished = false;
    if (!state.awaiting_seek && (!(state.paused && state.started) || state.show_while_paused)) {
      double visible_at = clock.now() + seen_after();
      // The clock waits, paused, for the first frame to be on screen; a stream whose video starts
      // later than its sound (mkv: video at 0.023 s, audio at 0) would wait for it for ever. The
      // first frame is the poster shown while the clock waits, whenever its pts.
      if (!state.started && !queued.empty()) visible_at = std::max(visible_at, queued.front());
      const FrameDecision d = scheduler.decide(visible_at, queued, end);
      if (d.drop > 0 || d.show_front) {
        if (auto frame = queue.pop(d.drop, d.show_front)) {
          state.show_while_paused = false;
          state.current = std::move(frame);
          const auto t = Steady::now();
          compositor.prepare(state.current, commands.overlays());
          if (log.enabled()) glFinish();  // so that the log says where the time goes
          upload_s = seconds_since(t);
          state.dirty = true;
          event = "shown";
        }
      }
      if (d.repeat) event = "repeated";
      finished = d.finished;
    }
    commands.expire_message();
    if (finished) break;

    bool ahead = false;
    if (state.dirty) {
      auto t = Steady::now();
      ahead = compositor.render(state.current, commands.overlays(), {target});
      if (ahead) ++result.composited_ahead;
      if (log.enabled()) glFinish();
      render_only_s = seconds_since(t);
      if (options.after_render) options.after_render(display, state.current ? state.current->pts_s : 0.0);
      t = Steady::now();
      try {
        display.present();
      } catch (const std::runtime_error& e) {
        throw UserError(fmt::format("the display was lost: {}", e.what()), 1);
      }
      present_s = seconds_since(t);
      state.dirty = false;
      if (state.started) render_time.add(seconds_since(decided_at));
      if (!state.started) {
        state.started = true;
        if (!state.paused && !state.awaiting_seek) start_clock();
      }
      if (!event) event = "redrawn";
    } else if (display.vsync()) {
      display.present();  // paces the loop at the refresh
    }
    if (event)
      log.write(refresh, event, state.current ? std::optional(state.current->pts_s) : std::nullopt, clock.now(),
                sound.output() ? std::optional(sound.output()->now()) : std::nullopt, scheduler.counters(), upload_s,
                render_only_s, present_s, queued.size(), ahead);
    ++refresh;

    // The next frames, composited on the worker while this thread waits for the next refresh; not
    // those whose time will have passed by then (the next refresh drops them): after a slow spell
    // the worker would otherwise spend itself on frames never shown.
    {
      const std::vector<FrameQueue::Frame> next = queue.front(queue_capacity);
      std::vector<double> next_pts;
      for (const auto& f : next) next_pts.push_back(f->pts_s);
      const std::size_t stale = scheduler.stale(clock.now() + refresh_period + seen_after(), next_pts);
      compositor.composite_ahead(std::span(next).subspan(stale), commands.overlays(), target);
    }

    if (!display.vsync()) ticker.sleep_to_next();
  }

  queue.stop();
  decoder.join();
  result.audio_decode_errors = sound.decode_errors();
  sound.stop();
  result.counters = scheduler.counters();
  result.video_decode_errors = source.lost_frames();
  return result;
}

}  // namespace nelf
