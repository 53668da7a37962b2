#pragma once
// What `nelf play` sets up before its loop (player.cpp) and holds while it runs: the compositor on
// the display's packed frame, the frame log, the sound and the master clock it gives, the pacing,
// the decoded frames and their thread, the state the keys change. The members are in the order
// they are made: each check and each thread starts where it did when this was one function, and
// they stop in reverse (the decoder before the queue, the sound before the source).
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "compositor/frame_compositor.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/packing.hpp"
#include "inputs/source.hpp"
#include "player/frame_log.hpp"
#include "player/frame_queue.hpp"
#include "player/frame_scheduler.hpp"
#include "player/ipc_server.hpp"
#include "player/play_commands.hpp"
#include "player/play_sound.hpp"
#include "player/player.hpp"
#include "player/refresh_pacing.hpp"

namespace nelf::playback {

struct PlaySession {
  // Throws UserError when the panel does not fit the signal or the display's frame, or the frame
  // log cannot be written. Prints the sound's status line unless options.quiet.
  PlaySession(Display& display, Source& source, const PlayerOptions& options, const std::atomic<bool>* stop);
  PlaySession(const PlaySession&) = delete;
  PlaySession& operator=(const PlaySession&) = delete;

  // Waits (briefly, polling the display) for the first frame, so that the clock does not run ahead
  // of a slow start; for a live source, composites it once unseen so that the first composite's
  // set-up does not hold up the frames after it.
  void wait_for_first_frame();
  // Tells a live source when the next refresh begins, before the loop reaches it (no vsync).
  void announce_next_refresh();
  // Source::refresh_at of the refresh beginning at `refresh`, a period long.
  void tell_source_refresh(std::chrono::steady_clock::time_point refresh);
  // The keys since the last refresh carried out; why play ends now, if it does.
  std::optional<PlayEnd> take_keys_and_events();
  // Starts the clock (after the first frame, or a seek) once the next frames are composited ahead.
  void start_clock();
  // When a refresh starting now will be seen, after the master clock's now.
  double seen_after() const;
  // To the next refresh: with vsync, present() has waited; without, the ticker sleeps to it (a
  // stepped clock is advanced instead).
  void wait_for_next_refresh();
  // Stops the decoder and the sound; the counts of the run.
  PlayResult finish(std::int64_t composited_ahead);

  static constexpr std::size_t queue_capacity = 6;

  Display& display;
  Source& source;
  const PlayerOptions& options;
  const std::atomic<bool>* stop;
  const PackedLayout layout;  // made once the image library is loaded and the display's context current
  FrameCompositor compositor;
  const GlPackedTarget target;  // made once the eyes are checked to fit it
  FrameLog log;
  std::shared_ptr<IpcServer> ipc;  // --input-ipc-server (the playlist's), polled once a refresh
  PlaySound sound;
  PlaybackClock& clock;  // the master clock, paused until the first frame is on screen
  const double refresh_period;
  const SourceInfo info;
  FrameScheduler scheduler;
  const ViewFormat view_format;  // negotiated before the first frame is decoded
  FrameQueue queue;
  SubtitleControls subtitles{options.subtitles, options.sub_depth};  // before the decoder, which reads them
  std::jthread decoder;
  // Unblocks the decoder before it is joined, however play ends (a live source may be waiting for
  // a frame).
  struct StopDecoder {
    FrameQueue& queue;
    Source& source;
    ~StopDecoder() {
      source.interrupt();
      queue.stop();
    }
  } stop_decoder{queue, source};
  PlayState state;
  PlayCommands commands;
  RenderTime render_time;  // the first render, which compiles shaders, does not count
  RefreshTicker ticker;
  std::vector<KeyPress> early_keys;  // typed while waiting for the first frame
};

}  // namespace nelf::playback
