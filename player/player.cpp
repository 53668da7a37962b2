#include "player/player.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <optional>

#include "player/play_session.hpp"
#include "player/refresh_step.hpp"

namespace nelf {

std::string play_summary(const PlayResult& r) {
  std::string line = fmt::format("{} frames shown, {} repeated, {} dropped", r.counters.shown, r.counters.repeated,
                                 r.counters.dropped);
  if (r.video_decode_errors > 0) line += fmt::format(", {} video frames lost to decode errors", r.video_decode_errors);
  if (r.audio_decode_errors > 0) line += fmt::format(", {} audio decode errors", r.audio_decode_errors);
  return line;
}

namespace {

// A photo has had its one frame's time when it is first on screen: it stays until a key, the window
// or Ctrl-C ends play, or for --image-duration on the master clock (paused, it waits).
bool holds_still(playback::PlaySession& session) {
  if (!session.info.still) return false;
  return !session.options.image_duration_s || session.clock.now() < *session.options.image_duration_s;
}

}  // namespace

// The pipeline, once per refresh: keys, the frame the clock asks for, render and present, the log,
// the next frames composited ahead, the wait for the next refresh.
PlayResult play(Display& display, Source& source, const PlayerOptions& options, const std::atomic<bool>* stop) {
  playback::PlaySession session(display, source, options, stop);
  if (options.start_s) session.commands.seek_to(*options.start_s, "");
  if (!options.announce.empty()) session.commands.say(options.announce);
  session.wait_for_first_frame();
  PlayEnd end = PlayEnd::end_of_file;
  std::int64_t composited_ahead = 0;
  for (std::int64_t refresh = 0;; ++refresh) {
    if (const std::optional<PlayEnd> why = session.take_keys_and_events()) {
      end = *why;
      break;
    }
    playback::Refresh step = playback::choose_frame(session);
    session.commands.expire_message();
    session.commands.update_preview_caption();
    if (step.finished && !holds_still(session)) break;
    playback::present_frame(session, step);
    if (step.ahead) ++composited_ahead;
    playback::log_refresh(session, refresh, step);
    playback::composite_next_ahead(session);
    session.wait_for_next_refresh();
  }
  PlayResult result = session.finish(composited_ahead);
  result.end = end;
  return result;
}

}  // namespace nelf
