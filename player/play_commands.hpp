#pragma once
// What the keys do during `nelf play` (player/key_bindings.cpp maps keys to these commands): pause,
// seek, the screen's distance and the IPD, swapping the eyes, the calibration grid, fullscreen and
// the key help, each with its on-screen message. The play loop reads the state they leave.
#include <chrono>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "compositor/compositor.hpp"
#include "core/frames.hpp"
#include "hmz_output/display.hpp"
#include "inputs/source.hpp"
#include "optics/profile.hpp"
#include "player/frame_queue.hpp"
#include "player/frame_scheduler.hpp"
#include "player/key_bindings.hpp"
#include "player/packed_renderer.hpp"
#include "player/play_sound.hpp"

namespace nelf::playback {

// Views as the prefilter's block means where the input allows (swscale makes them while
// converting from YUV): far less to convert, upload and composite per frame. The block follows
// the optics.
ViewFormat view_format_for(const Profile& profile, const CompositorOptions& compositor, const ViewGeometry& view);

struct PlayState {
  bool paused = false;
  bool started = false;  // the first frame is on screen (the clock waits for it)
  bool calibration = false;
  bool swap_eyes = false;
  bool dirty = false;              // the packed frame must be rendered again
  bool awaiting_seek = false;      // the clock waits, paused, for the first frame after a seek
  bool show_while_paused = false;  // a seek while paused shows the first frame at the new place
  std::shared_ptr<const StereoVideoFrame> current;
};

class PlayCommands {
 public:
  PlayCommands(PlayState& state, Display& display, PackedRenderer& renderer, FrameQueue& queue, PlaySound& sound,
               FrameScheduler& scheduler, const PlayerOptions& options, std::optional<double> duration_s,
               ViewGeometry view)
      : state_(state),
        display_(display),
        renderer_(renderer),
        queue_(queue),
        sound_(sound),
        scheduler_(scheduler),
        options_(options),
        duration_s_(duration_s),
        view_(view) {}

  // Carries out `command`; false for quit.
  bool apply(Command command);
  // A message on screen for two seconds (when on-screen messages are on); the frame is redrawn.
  void say(std::string text);
  // Takes the message off the screen once its two seconds are up.
  void expire_message();

 private:
  void seek_by(double delta_s);
  void change_profile(const Profile& changed, const std::string& what);

  PlayState& state_;
  Display& display_;
  PackedRenderer& renderer_;
  FrameQueue& queue_;
  PlaySound& sound_;
  FrameScheduler& scheduler_;
  const PlayerOptions& options_;
  std::optional<double> duration_s_;
  ViewGeometry view_;          // the source's, for the view format a change of the optics asks for
  std::size_t help_line_ = 0;  // the next line of the key help that h shows
  std::string message_;
  std::chrono::steady_clock::time_point message_until_{};
};

}  // namespace nelf::playback
