#include "player/refresh_step.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <span>
#include <stdexcept>
#include <utility>

#include "core/frame_stamp.hpp"
#include "core/user_error.hpp"

namespace nelf::playback {

namespace {
using Steady = std::chrono::steady_clock;
double seconds_since(Steady::time_point t) { return std::chrono::duration<double>(Steady::now() - t).count(); }
}  // namespace

Refresh choose_frame(PlaySession& s) {
  PlayState& state = s.state;
  Refresh r;
  r.decided_at = Steady::now();
  if (s.options.clock) s.queue.wait_until_full();  // a stepped clock waits for the decoder
  bool end = false;
  r.queued = s.queue.snapshot(end);
  if (state.awaiting_seek && (!r.queued.empty() || end)) {
    state.awaiting_seek = false;
    state.show_while_paused = state.paused;
    if (!state.paused) s.start_clock();
  }
  if (state.awaiting_seek || (state.paused && state.started && !state.show_while_paused)) return r;
  double visible_at = s.clock.now() + s.seen_after();
  // The clock waits, paused, for the first frame to be on screen; a stream whose video starts
  // later than its sound (mkv: video at 0.023 s, audio at 0) would wait for it for ever. The
  // first frame is the poster shown while the clock waits, whenever its pts.
  if (!state.started && !r.queued.empty()) visible_at = std::max(visible_at, r.queued.front());
  // A live source (a game's window) is shown as it comes: the newest frame read is due now, the
  // older ones are dropped, whatever the clock says (its frames are made in real time, they are
  // never early).
  if (s.info.live && !r.queued.empty()) visible_at = std::max(visible_at, r.queued.back());
  const FrameDecision d = s.scheduler.decide(visible_at, r.queued, end);
  if (d.drop > 0 || d.show_front) {
    if (auto frame = s.queue.pop(d.drop, d.show_front)) {
      state.show_while_paused = false;
      state.current = std::move(frame);
      const auto t = Steady::now();
      s.compositor.prepare(state.current, s.commands.overlays());
      if (s.log.enabled()) glFinish();  // so that the log says where the time goes
      r.upload_s = seconds_since(t);
      state.dirty = true;
      r.event = "shown";
    }
  }
  if (d.repeat) r.event = "repeated";
  r.finished = d.finished;
  return r;
}

void present_frame(PlaySession& s, Refresh& r) {
  PlayState& state = s.state;
  if (!state.dirty) {
    s.commands.take_pending_screenshot();        // the frame the display keeps showing
    if (s.display.vsync()) s.display.present();  // paces the loop at the refresh
    return;
  }
  auto t = Steady::now();
  r.ahead = s.compositor.render(state.current, s.commands.overlays(), {s.target});
  if (s.log.enabled()) glFinish();
  r.render_s = seconds_since(t);
  if (s.options.after_render) s.options.after_render(s.display, state.current ? state.current->pts_s : 0.0);
  s.commands.take_pending_screenshot();
  t = Steady::now();
  try {
    s.display.present();
  } catch (const std::runtime_error& e) {
    throw UserError(fmt::format("the display was lost: {}", e.what()), 1);
  }
  r.present_s = seconds_since(t);
  r.presented_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Steady::now().time_since_epoch()).count();
  state.dirty = false;
  if (state.started) s.render_time.add(seconds_since(r.decided_at));
  if (!state.started) {
    state.started = true;
    if (!state.paused && !state.awaiting_seek) s.start_clock();
  }
  if (!r.event) r.event = "redrawn";
}

void log_refresh(PlaySession& s, std::int64_t index, const Refresh& r) {
  if (!r.event || !s.log.enabled()) return;  // no stamp read on a refresh nobody logs
  const FrameCompositor::Frame& current = s.state.current;
  LiveFrameTimes live;
  if (s.info.live && current) {
    live.presented_ns = r.presented_ns;
    live.captured_ns = current->captured_ns;
    // A game that stamps its frames (tests/game/) says which one this is and when it presented it
    // (its cells are fractions of the view: they read from block means too).
    live.game = read_frame_stamp(current->left.data(), current->width / current->block[0],
                                 current->height / current->block[1], current->bits);
  }
  s.log.write(index, r.event, current ? std::optional(current->pts_s) : std::nullopt, s.clock.now(),
              s.sound.output() ? std::optional(s.sound.output()->now()) : std::nullopt, s.scheduler.counters(),
              r.upload_s, r.render_s, r.present_s, r.queued.size(), r.ahead, live);
}

// Not the frames whose time will have passed by the next refresh (it drops them): after a slow
// spell the worker would otherwise spend itself on frames never shown.
void composite_next_ahead(PlaySession& s) {
  const std::vector<FrameQueue::Frame> next = s.queue.front(PlaySession::queue_capacity);
  std::vector<double> next_pts;
  for (const auto& f : next) next_pts.push_back(f->pts_s);
  const std::size_t stale = s.scheduler.stale(s.clock.now() + s.refresh_period + s.seen_after(), next_pts);
  s.compositor.composite_ahead(std::span(next).subspan(stale), s.commands.overlays(), s.target);
}

}  // namespace nelf::playback
