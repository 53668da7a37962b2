#pragma once
// The player engine behind `nelf play` (DESIGN.md §7): a decode thread fills a bounded queue of
// stereo frames; the display's thread (the caller's) paces them against the master clock with
// FrameScheduler, uploads each new frame's two views once, composites both eyes with GlCompositor
// straight into the display's packed framebuffer (on software GL, 8-bit block means: from composite
// tables on the CPU, the next frames ahead on a worker thread (CompositeAhead), then one upload of
// the packed frame) and presents. An audio thread feeds SDL2 audio, whose clock is master; without
// sound a system clock is. Keys change playback and the optics live.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "compositor/compositor.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/signal.hpp"
#include "inputs/source.hpp"
#include "inputs/subtitle_track.hpp"
#include "optics/profile.hpp"
#include "player/frame_scheduler.hpp"
#include "player/ipc_server.hpp"
#include "player/key_bindings.hpp"
#include "player/stepped_clock.hpp"
#include "player/subtitle_choice.hpp"
#include "player/subtitle_depth.hpp"

namespace nelf {

struct PlayerOptions {
  Profile profile;
  Signal signal;
  CompositorOptions compositor;
  bool audio = true;                           // false: --no-audio
  std::string no_audio_reason = "--no-audio";  // what the status line says when audio is false
  int audio_rate = 48000;
  std::optional<int> audio_track;            // --aid N: the file's N-th audio track
  std::vector<std::string> audio_languages;  // --alang: the first track in the first of these
  double volume = 100.0;                     // --volume, 0 to 130 (100: as decoded)
  bool mute = false;
  std::string log_frames;        // CSV of every refresh (diagnostics); "" = none
  bool quiet = false;            // no "playing …" / audio status lines on stderr (warnings still are)
  KeyRebindings key_rebindings;  // the configuration file's [keys]
  // --input-ipc-server: mpv's JSON IPC, listening for the whole playlist (its clients stay connected
  // from one file to the next, as mpv's do); null: none.
  std::shared_ptr<playback::IpcServer> ipc_server;
  std::string media_path;  // the input as given (the IPC's path and filename properties)
  // Each key's change said on screen for 2 s. Off (tests): while a message shows, frames are
  // composited with GL (the text is drawn there), so without them the CPU path and its frames
  // composited ahead are seen right after a key.
  bool on_screen_messages = true;
  // Drawn into both views of every frame as it is decoded (null: none), the left eye's copy
  // sub_depth's parallax (a fixed one, or just in front of the content beneath: --sub-parallax auto)
  // of the view width right of the right eye's.
  std::shared_ptr<SubtitleTrack> subtitles;
  SubtitleDepth sub_depth;
  // What the subtitle track keys (j J) and the IPC's sid switch among (subtitle_tracks), the
  // bitmaps of each laid out as `sub_stereo` says; empty: the subtitles there are cannot change.
  std::vector<SubtitleTrackRef> subtitle_tracks;
  SubtitleStereo sub_stereo = SubtitleStereo::flat;
  // Called after each new frame is rendered into the packed framebuffer, before present(); the
  // display's context is current (tests read the frame back here).
  std::function<void(const Display&, double pts_s)> after_render;
  // Tests: the master clock instead of the sound's or the system's, advanced one refresh period
  // after each refresh instead of waiting for the next one. Rendering takes no time on it, and each
  // refresh waits for the decoder to fill the queue (or end), so that the frames shown, repeated
  // and dropped are what FrameScheduler makes of the clip's timestamps and the refresh rate.
  std::shared_ptr<playback::SteppedClock> clock;
  // A photo (SourceInfo::still) stays on screen until q, the window closing or Ctrl-C; with this,
  // for this long on the master clock (a slideshow: the pause key holds it).
  std::optional<double> image_duration_s;
  // Where play starts, in the movie's time (--start, or where the user stopped last time).
  std::optional<double> start_s;
  // The files of the playlist before and after this one: what the keys for the next and the
  // previous file can go to.
  bool has_next = false;
  bool has_previous = false;
  // Opens the input again, for a screenshot of the views (Ctrl+v), which decodes the frame on
  // screen once more at full resolution; null (a live input, a pipe): the views as they are shown.
  std::function<std::unique_ptr<Source>()> reopen_input;
  // Said on screen with the first frame ("resuming at 0:12:34", "2/5: photo.jps"); "" for none.
  std::string announce;
};

// next_file / previous_file: the user asked for another file of the playlist.
enum class PlayEnd { end_of_file, quit_key, window_closed, interrupted, next_file, previous_file };

struct PlayResult {
  PlayEnd end = PlayEnd::end_of_file;
  FrameCounters counters;
  std::int64_t video_decode_errors = 0;
  std::int64_t audio_decode_errors = 0;
  std::int64_t composited_ahead = 0;  // frames shown as composited ahead on a worker (CPU path)
  bool had_sound = false;
  std::string sound;  // "pulseaudio, 48000 Hz …" or why there was none
  // Where play stopped, in the movie's time (the target of a seek not yet shown); none when nothing
  // was shown.
  std::optional<double> position_s;
  bool eyes_swapped = false;  // the user swapped the eyes (key s) an odd number of times
  // The subtitles' depth at the end (there were some): a fixed parallax, or auto's margin.
  std::optional<SubtitleDepth> sub_depth;
};

// Plays `source` on `display` until the end of the file, q/Esc, the window closing or `*stop`
// becoming true (SIGINT/SIGTERM). Must be called on the display's thread. Throws UserError for
// unusable input or outputs (the panel does not fit the signal, the display is lost).
PlayResult play(Display& display, Source& source, const PlayerOptions& options,
                const std::atomic<bool>* stop = nullptr);

// The one line printed at exit: "played 48 frames: 48 shown, 0 repeated, 0 dropped".
std::string play_summary(const PlayResult& result);

}  // namespace nelf
