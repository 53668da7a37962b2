#include "player/play_session.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cstdio>

#include "compositor/overlays/subtitle_overlay.hpp"
#include "core/image_library.hpp"
#include "core/user_error.hpp"
#include "player/ipc_commands.hpp"
#include "player/key_bindings.hpp"

namespace nelf::playback {

namespace {

// The subtitles drawn into each frame on the decode thread: the frame's pts after a seek as before,
// and the view's compositing untouched (GL, the tables and the frames composited ahead alike).
std::function<void(StereoVideoFrame&)> subtitle_drawing(const PlayerOptions& options, SubtitleControls& controls) {
  if (!options.subtitles && options.subtitle_tracks.empty()) return {};
  // Shared: the decoder's function is copied; the follower keeps the line being read.
  auto follower = std::make_shared<SubtitleDepthFollower>();
  return [&controls, follower](StereoVideoFrame& frame) {
    const std::shared_ptr<SubtitleTrack> track = controls.track.load();
    if (!track || !controls.shown) return;
    const auto [width, height] = subtitle_canvas(frame);
    const SubtitleBitmap subtitle = track->render(frame.pts_s, width, height, frame.aspect);
    const double parallax = follower->parallax(frame, subtitle, controls.depth());
    controls.drawn_percent = parallax;
    draw_subtitles(frame, subtitle, parallax);
  };
}

// The on-screen messages draw their text with OpenImageIO, loaded on first use: load it now
// (~0.3 s) rather than as a hitch at the first key press. Without it the film still plays; the
// first message then stops play with the same error, as a missing font would.
PackedLayout prepared_layout(Display& display, const PlayerOptions& options) {
  try {
    image_library::preload();
  } catch (const image_library::ImageLibraryError& e) {
    std::fprintf(stderr, "nelf: warning: %s\n", e.what());
  }
  display.context()->make_current();
  return packed_layout(options.signal, options.profile.display.resolution);
}

// The display's packed frame, once both eyes are known to fit it; the compositor gets the grid.
GlPackedTarget checked_target(const Display& display, FrameCompositor& compositor, const PackedLayout& layout,
                              const PlayerOptions& options) {
  require_eyes_fit(layout, options.profile.name, options.signal.name);
  const std::array<int, 2> packed = display.packed_size();
  for (const auto& origin : layout.origins)
    if (origin && (origin->first + layout.eye[0] > packed[0] || origin->second + layout.eye[1] > packed[1]))
      throw UserError(fmt::format("the display's {}x{} frame is smaller than signal {} needs", packed[0], packed[1],
                                  options.signal.name),
                      1);
  compositor.set_grid_pattern(calibration_grid_pattern());
  return GlPackedTarget{display.packed_framebuffer(), display.packed_texture(), packed};
}

// The master clock: the sound's when there is sound (the tests' stepped clock when they give one). It starts with the
// first frame on screen.
PlaybackClock& paused_master_clock(PlaySound& sound, const PlayerOptions& options) {
  if (!options.quiet)
    std::fprintf(stderr, sound.playing() ? "nelf: sound: %s\n" : "nelf: %s: playing without sound\n",
                 sound.description().c_str());
  PlaybackClock& clock = options.clock ? *options.clock : sound.clock();
  clock.set_paused(true);
  return clock;
}

}  // namespace

PlaySession::PlaySession(Display& display_, Source& source_, const PlayerOptions& options_,
                         const std::atomic<bool>* stop_)
    : display(display_),
      source(source_),
      options(options_),
      stop(stop_),
      layout(prepared_layout(display, options)),
      compositor(options.profile, options.compositor, layout, display.context()),
      target(checked_target(display, compositor, layout, options)),
      log(options.log_frames),
      ipc(options.ipc_server),
      sound(source, options),
      clock(paused_master_clock(sound, options)),
      refresh_period(1.0 / display.refresh_hz()),
      info(source.info()),
      // A live source's rate is the most it reads (x11: fps=), not the game's: its period is
      // estimated from the frames, so that a refresh without a new one is a repeat only when the
      // game is late for its own cadence.
      scheduler(refresh_period, info.frame_rate > 0 && !info.live ? 1.0 / info.frame_rate : 0.0),
      view_format(source.negotiate(compositor.wanted_view_format(info.view))),
      queue(queue_capacity, info.live ? FrameQueue::WhenFull::drop_oldest : FrameQueue::WhenFull::wait),
      decoder([this] { decode_loop(source, queue, subtitle_drawing(options, subtitles)); }),
      commands(state, display, compositor, queue, sound, scheduler, options, info.duration_s, info.view, info.still,
               options.subtitles || !options.subtitle_tracks.empty() ? &subtitles : nullptr),
      render_time(refresh_period),
      ticker(refresh_period) {}

void PlaySession::wait_for_first_frame() {
  while (!queue.wait_for_frame(std::chrono::milliseconds(50))) {
    bool end = false;
    queue.snapshot(end);
    if (end || (stop && stop->load()) || display.close_requested()) return;
    // Kept for the first refresh: a key typed while the file opens is not lost.
    for (const KeyPress& key : display.poll_events()) early_keys.push_back(key);
  }
  // A live source's game goes on drawing while nelf makes its first composite (the composite tables
  // loaded or recorded for the views' size, the shaders compiled at their first draw: 0.2 s on
  // llvmpipe), and the frames it drew meanwhile were overtaken by the next one shown: most of the
  // frames a game lost (docs/PERFORMANCE.md, live games). That first composite is made, unseen, of
  // the first frame, and the first frame shown is then the newest. (A file's frames wait for the
  // clock instead, which starts after the first is shown.)
  if (!info.live) return;
  // And the refreshes to come are said from now on, around that composite rather than after the
  // first refresh: a game timing its swaps to them (a quad-buffer game with vsync) is in step from
  // its next frame, not two or three frames late.
  announce_next_refresh();
  if (const std::vector<FrameQueue::Frame> first = queue.front(1); !first.empty())
    compositor.render(first.front(), commands.overlays(), {target});
  announce_next_refresh();
}

// Without vsync the ticker's next tick is known ahead (with vsync, present() says when a refresh
// begins: wait_for_next_refresh).
void PlaySession::announce_next_refresh() {
  if (options.clock || display.vsync()) return;
  tell_source_refresh(ticker.next_after(std::chrono::steady_clock::now()));
}

void PlaySession::tell_source_refresh(std::chrono::steady_clock::time_point refresh) {
  using namespace std::chrono;
  source.refresh_at(duration_cast<nanoseconds>(refresh.time_since_epoch()).count(),
                    duration_cast<nanoseconds>(duration<double>(refresh_period)).count());
}

std::optional<PlayEnd> PlaySession::take_keys_and_events() {
  std::vector<KeyPress> keys = std::move(early_keys);
  early_keys.clear();
  for (const KeyPress& key : display.poll_events()) keys.push_back(key);
  std::optional<PlayEnd> why;
  for (const KeyPress& key : keys)
    if (const std::optional<Command> command = command_for(KeyScope::play, key, options.key_rebindings))
      if (const std::optional<PlayEnd> end = commands.apply(*command); end && !why) why = end;
  if (ipc) {
    IpcTarget remote{state, commands, info.duration_s, options.media_path, options.key_rebindings, {}};
    ipc->poll([&](std::string_view line) { return answer_ipc_request(line, remote); });
    if (remote.end && !why) why = remote.end;
  }
  if (why) return why;
  if (display.close_requested()) return PlayEnd::window_closed;
  if (stop && stop->load()) return PlayEnd::interrupted;
  return std::nullopt;
}

// Before the clock starts (after the first frame) or restarts (after a seek): the next frames
// composited ahead, waiting up to 0.3 s. The worker's first frames take 40 ms and more (new
// buffers, cold caches), and with the clock running the first refreshes dropped frames waiting
// for them (2 of 300 at 30 fps in a run of tests/bench/play_pacing.sh). Not for a live source:
// its frames are shown newest first, not on the clock, and the game goes on drawing meanwhile.
void PlaySession::start_clock() {
  compositor.composite_ahead(queue.front(queue_capacity), commands.overlays(), target);
  if (!info.live) compositor.wait_for_ahead(std::chrono::milliseconds(300));
  clock.set_paused(false);
}

// After the next vblank, or once rendered and presented (at once on a stepped clock).
double PlaySession::seen_after() const {
  if (options.clock) return 0.0;
  return display.vsync() ? refresh_period : render_time.median_s();
}

void PlaySession::wait_for_next_refresh() {
  if (options.clock) {
    options.clock->advance(refresh_period);
    return;
  }
  if (!display.vsync()) ticker.sleep_to_next();
  // A refresh begins (with vsync, present() returned at it): a live source may time its frames to
  // it (a quad-buffer game's swaps).
  tell_source_refresh(display.vsync() ? std::chrono::steady_clock::now() : ticker.tick());
}

PlayResult PlaySession::finish(std::int64_t composited_ahead) {
  source.interrupt();
  queue.stop();
  decoder.join();
  commands.finish_screenshots();
  PlayResult result;
  result.had_sound = sound.playing();
  result.sound = sound.description();
  result.audio_decode_errors = sound.decode_errors();
  sound.stop();
  result.counters = scheduler.counters();
  result.video_decode_errors = source.lost_frames();
  result.composited_ahead = composited_ahead;
  if (state.awaiting_seek)
    result.position_s = state.seek_target_s;
  else if (state.current)
    result.position_s = state.current->pts_s;
  result.eyes_swapped = state.swap_eyes;
  if (options.subtitles || !options.subtitle_tracks.empty()) result.sub_depth = subtitles.depth();
  return result;
}

}  // namespace nelf::playback
