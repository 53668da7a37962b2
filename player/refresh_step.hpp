#pragma once
// The steps of one refresh of `nelf play` after the keys (player.cpp runs them in order): choose
// the frame to show, render and present it, log the refresh, composite the next frames ahead.
#include <chrono>
#include <cstdint>
#include <vector>

#include "player/play_session.hpp"

namespace nelf::playback {

// What one refresh did, for the frame log.
struct Refresh {
  std::chrono::steady_clock::time_point decided_at;
  const char* event = nullptr;  // "shown", "repeated", "redrawn"; null when nothing changed on screen
  std::vector<double> queued;   // pts of the decoded frames waiting at the decision
  bool finished = false;        // the last frame has had its time: play is over
  bool ahead = false;           // the frame rendered was composited ahead by the worker
  double upload_s = 0.0, render_s = 0.0, present_s = 0.0;
  std::int64_t presented_ns = 0;  // CLOCK_MONOTONIC once presented (0: nothing presented)
};

// Which frame this refresh shows, as the scheduler decides on the master clock: it is taken from
// the queue and its views uploaded. After a seek, the clock restarts with the first new frame.
Refresh choose_frame(PlaySession& session);

// Renders the frame on screen when it changed and presents it (with vsync, presenting the same
// frame paces the loop); the first frame on screen starts the clock. Throws UserError when the
// display is lost.
void present_frame(PlaySession& session, Refresh& refresh);

// The refresh's line of --log-frames, when something changed on screen.
void log_refresh(PlaySession& session, std::int64_t index, const Refresh& refresh);

// The next frames, composited on the worker while this thread waits for the next refresh.
void composite_next_ahead(PlaySession& session);

}  // namespace nelf::playback
