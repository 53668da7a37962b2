#pragma once
// What the keys do during `nelf play` (player/key_bindings.cpp maps keys to these commands): pause,
// seek (with the time line and seek bar), the screen's distance and the IPD, swapping the eyes, the
// calibration grid, fullscreen, volume, mute, the audio track and the key help, each with its
// on-screen message. The play loop reads the state they leave.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <future>
#include <memory>
#include <optional>
#include <string>

#include "compositor/compositor.hpp"
#include "compositor/frame_compositor.hpp"
#include "compositor/overlays/text_overlay.hpp"
#include "core/frames.hpp"
#include "hmz_output/display.hpp"
#include "inputs/source.hpp"
#include "optics/profile.hpp"
#include "player/frame_queue.hpp"
#include "player/frame_scheduler.hpp"
#include "player/key_bindings.hpp"
#include "player/play_sound.hpp"
#include "player/player.hpp"
#include "player/subtitle_choice.hpp"

namespace nelf::playback {

// The calibration grid (key c): calibrate's grid pattern at the views' size and the optics.
FrameCompositor::GridPattern calibration_grid_pattern();

// What the decoder reads as it draws the subtitles into each frame, and the keys change: the track
// (j J: null for none; replaced on the display's thread while the decoder holds the one it draws
// with), whether they show (v) and their depth (r R), in percent of the view width: the parallax,
// or with `follows_content` (--sub-parallax auto) how far in front of the content beneath. The
// decoder leaves the parallax it drew the last frame's at in `drawn_percent` (a views screenshot
// draws them the same).
struct SubtitleControls {
  SubtitleControls(std::shared_ptr<SubtitleTrack> first, SubtitleDepth depth)
      : track(std::move(first)),
        follows_content(depth.follows_content),
        parallax_percent(depth.percent),
        drawn_percent(depth.follows_content ? 0.0 : depth.percent) {}
  SubtitleDepth depth() const { return {follows_content, parallax_percent}; }
  std::atomic<std::shared_ptr<SubtitleTrack>> track;
  std::atomic<bool> shown{true};
  const bool follows_content;
  std::atomic<double> parallax_percent;
  std::atomic<double> drawn_percent;
};

struct PlayState {
  bool paused = false;
  bool started = false;  // the first frame is on screen (the clock waits for it)
  bool calibration = false;
  bool swap_eyes = false;
  bool dirty = false;              // the packed frame must be rendered again
  bool awaiting_seek = false;      // the clock waits, paused, for the first frame after a seek
  double seek_target_s = 0.0;      // where the last seek went (the position while awaiting_seek)
  bool show_while_paused = false;  // a seek while paused shows the first frame at the new place
  std::shared_ptr<const StereoVideoFrame> current;
};

class PlayCommands {
 public:
  PlayCommands(PlayState& state, Display& display, FrameCompositor& compositor, FrameQueue& queue, PlaySound& sound,
               FrameScheduler& scheduler, const PlayerOptions& options, std::optional<double> duration_s,
               ViewGeometry view, bool still, SubtitleControls* subtitles = nullptr)
      : state_(state),
        display_(display),
        compositor_(compositor),
        queue_(queue),
        sound_(sound),
        scheduler_(scheduler),
        options_(options),
        duration_s_(duration_s),
        view_(view),
        still_(still),
        subtitles_(subtitles),
        subtitle_index_(index_of_first_track(options)) {}

  // Carries out `command`; why play ends now, if it does (quit, another file of the playlist).
  std::optional<PlayEnd> apply(Command command);
  // Goes to `seconds` in the movie's time (clamped to it) as a seek key does, saying `what` on screen
  // ("" for nothing).
  void seek_to(double seconds, const std::string& what);
  // Seeks `delta_s` from the frame on screen (as the arrows do), or to `target_s`, with the time
  // line and the seek bar after it as mpv's OSD.
  void seek_by(double delta_s);
  void seek_shown(double target_s);
  // The sound's volume (0 to 130) and mute, as the keys 9 0 m change them, saying so on screen.
  double volume() const { return sound_.volume(); }
  bool muted() const { return sound_.muted(); }
  void set_volume(double volume) { say(sound_.change_volume(volume - sound_.volume())); }
  void set_mute(bool mute) {
    if (mute != sound_.muted()) say(sound_.toggle_mute());
  }
  // The subtitle track shown, from 1 in options.subtitle_tracks (0: none), and the one to show
  // (0: none), as j J and the IPC's sid change it, saying so on screen. False when there is no
  // such track or it cannot be read (said on screen too).
  int subtitle_track() const { return subtitles_ && subtitles_->track.load() ? subtitle_index_ + 1 : 0; }
  bool set_subtitle_track(int number);
  // The audio track playing (its number, from 1; 0 when there is no sound), and the one to play.
  int audio_track() const { return sound_.track(); }
  int audio_track_count() const { return sound_.track_count(); }
  bool set_audio_track(int number);
  // A screenshot asked for (Ctrl+s) is taken once a frame is on the display: the packed frame
  // into the first free nelf-shotNNNN.png of the current folder; one of the views (Ctrl+v) is
  // written by a worker (player/views_screenshot), said when done. Called after each refresh's render.
  void take_pending_screenshot();
  // At the end of play: waits for a views screenshot still being written, and says how it went.
  void finish_screenshots();
  // A message on screen for two seconds (when on-screen messages are on); the frame is redrawn.
  void say(std::string text);
  // Takes the message off the screen once its two seconds are up.
  void expire_message();
  // The message (or the time line) as the display's preview caption, when it changed: flat over a
  // desktop window, where the views' copy is too small to read (Display::set_preview_caption).
  void update_preview_caption();
  // What the state asks to be drawn over the frame: the message (or the time line) with the seek
  // bar while it shows, the grid, the eyes swapped.
  FrameOverlays overlays() const;

 private:
  std::optional<PlayEnd> other_file(bool next);
  // Where options.subtitles is in options.subtitle_tracks; -1 for none.
  static int index_of_first_track(const PlayerOptions& options);
  // j / J: the next or previous of the subtitle tracks, "off" between the last and the first.
  void cycle_subtitles(int step);
  // The frames decoded ahead show what a key just changed (the subtitles, the audio track) as it
  // was: they are decoded again from the one on screen (a seek there).
  void decode_again_from_here();
  // Says how the views screenshot being written went, once it is done (or now when `wait`).
  void report_views_screenshot(bool wait);
  // A views screenshot of the frame on screen, on a worker.
  void start_views_screenshot();
  // The time line and the seek bar for two seconds (after a seek, key o).
  void show_progress();
  // Where playback is: the frame on screen, or where a seek goes.
  double position() const;
  void change_profile(const Profile& changed, const std::string& what);

  PlayState& state_;
  Display& display_;
  FrameCompositor& compositor_;
  FrameQueue& queue_;
  PlaySound& sound_;
  FrameScheduler& scheduler_;
  const PlayerOptions& options_;
  std::optional<double> duration_s_;
  ViewGeometry view_;                   // the source's, for the view format a change of the optics asks for
  bool still_;                          // a photo: ← and → step through the playlist instead of seeking
  SubtitleControls* subtitles_;         // read by the decoder as it draws them; null: no subtitles
  int subtitle_index_ = -1;             // in options_.subtitle_tracks; -1: none shown
  int screenshots_pending_ = 0;         // Ctrl+s pressed, taken after the next render
  int views_pending_ = 0;               // Ctrl+v pressed
  std::future<std::string> views_job_;  // the views being decoded again and written
  std::size_t help_line_ = 0;           // the next line of the key help that h shows
  std::string message_;
  std::unique_ptr<TextOverlay> caption_label_;  // made on the first caption
  FrameOverlays caption_shown_;                 // what the caption says now (its message and bar)
  std::chrono::steady_clock::time_point message_until_{};
  std::optional<std::chrono::steady_clock::time_point> progress_until_;
  bool keep_progress_ = false;  // key O
};

// "1:02:03": hours, minutes and seconds (whole seconds, rounded down), as the time line shows them.
std::string clock_time(double seconds);

}  // namespace nelf::playback
