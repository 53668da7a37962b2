// `nelf play IN...`: watch stereo videos and photos on the HMD (or a preview window) with sound:
// the player engine (player/player) on the display --output picks, one input after the other.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "app/commands.hpp"
#include "app/play_command.hpp"
#include "compositor/overlays/subtitle_overlay.hpp"
#include "core/printable.hpp"
#include "core/state_files.hpp"
#include "core/user_error.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/display_drivers.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/still_source.hpp"
#include "inputs/video_source.hpp"
#include "player/depth_input.hpp"
#include "player/interrupt.hpp"
#include "player/live_display.hpp"
#include "player/play_commands.hpp"
#include "player/play_sound.hpp"
#include "player/player.hpp"
#include "player/playlist.hpp"
#include "player/subtitle_choice.hpp"
#include "player/watch_later.hpp"

namespace nelf::app {

namespace {
KeyRebindings& rebound_keys() {
  static KeyRebindings keys;
  return keys;
}

void warn(const std::string& line) { fmt::print(stderr, "nelf: warning: {}\n", printable(line)); }

// An input read from stdin: the offscreen output then takes no keys from it.
bool reads_stdin(const std::string& input) { return input == "-" || input == "pipe:" || input == "pipe:0"; }

// One entry of the playlist: what is remembered of it applied (unless the command line says
// otherwise), played, and what the user left remembered.
// The display opens once the first entry has: a file that cannot be read is said before a window
// appears (or instead of the error that there is no display).
PlayResult play_entry(const PlayArgs& args, const CommonOptions& common, const std::function<Display&()>& display,
                      SourceRequest request, const WatchLater& watch_later, std::size_t index, std::size_t count,
                      const std::shared_ptr<playback::IpcServer>& ipc) {
  // Before it opens: an entry that fails is then named after its number.
  if (count > 1 && !args.quiet) fmt::print(stderr, "nelf: {}/{}: {}\n", index + 1, count, printable(request.input));
  const std::string path_name = std::filesystem::path(request.input).filename().string();
  const std::optional<std::string> key = args.remember ? WatchLater::key_for(request.input) : std::nullopt;
  const WatchLaterRecord record = key ? watch_later.load(*key, warn) : WatchLaterRecord{};
  request.right = args.right;
  request.layout = args.right.empty() ? common.layout : StereoLayout::pair;
  if (!common.layout && args.right.empty() && record.layout) {
    request.layout = parse_stereo_layout(*record.layout);
    if (request.layout && !args.quiet)
      fmt::print(stderr, "nelf: layout {} as last time (--layout overrides)\n", *record.layout);
  }
  request.swap_eyes = args.swap_eyes || record.swap_eyes.value_or(false);
  // The subtitles (--sub-file, a file beside the input, or its own first track) before the input
  // says its line: a --sub-file that does not parse is then the only one said. A photo has none;
  // a live window, a pipe or a URL is not looked into for them (one open of the input, behind
  // --allow-network).
  std::shared_ptr<SubtitleTrack> subtitles;
  std::error_code not_a_file;
  const SubtitleStreamChoice stream{parse_track_number(args.sid, "--sid"), args.slang};
  const SubtitleStereo sub_stereo = parse_sub_stereo(args.sub_stereo);
  const bool has_own_subtitles =
      args.subtitles && (!args.sub_file.empty() || std::filesystem::is_regular_file(request.input, not_a_file));
  if (has_own_subtitles && !args.no_subs && args.sid != "no")
    subtitles = choose_subtitles(request.input, args.sub_file, 0.0, false, args.quiet, stream, sub_stereo);
  const auto source = open_source_for_depth(request, common.compositor.depth, common.profile);
  const SourceInfo info = source->info();

  PlayerOptions options;
  // A views screenshot decodes the frame on screen again from the file (not from a pipe or a capture).
  if (!info.live && info.seekable && !reads_stdin(request.input))
    options.reopen_input = [request] {
      SourceRequest again = request;
      again.quiet = true;
      return open_source(again);
    };
  options.profile = common.profile;
  options.signal = common.signal;
  options.compositor = common.compositor;
  options.audio = !args.no_audio && args.aid != "no";
  options.audio_track = parse_track_number(args.aid, "--aid");
  if (args.aid == "no") options.no_audio_reason = "--aid no";
  options.audio_languages = args.alang;
  options.volume = args.volume;
  options.mute = args.mute;
  // A track that is not there is said before anything plays.
  if (options.audio) playback::choose_audio_track(source->audio_tracks(), options.audio_track, options.audio_languages);
  options.log_frames = args.log_frames;
  options.quiet = args.quiet;
  options.key_rebindings = rebound_keys();
  options.ipc_server = ipc;
  options.media_path = request.input;
  options.image_duration_s = args.image_duration;
  options.has_previous = index > 0;
  options.has_next = index + 1 < count;
  if (count > 1) options.announce = fmt::format("{}/{}: {}", index + 1, count, path_name);
  // Photos have no time to start at: --start and resuming are for the videos of the playlist.
  if (!info.still) {
    if (args.start) {
      if (info.duration_s && *args.start >= *info.duration_s)
        throw UserError(fmt::format("{}: --start {:g} is past the end of the video ({:.3g} s)",
                                    printable(request.input), *args.start, *info.duration_s),
                        1);
      options.start_s = args.start;
    } else if (args.resume && record.position_s && *record.position_s > 0 &&
               (!info.duration_s || *record.position_s < *info.duration_s)) {
      options.start_s = record.position_s;
      options.announce = fmt::format("resuming at {}", playback::clock_time(*record.position_s));
      if (!args.quiet)
        fmt::print(stderr, "nelf: resuming at {} (--no-resume starts from the beginning)\n",
                   playback::clock_time(*record.position_s));
    }
  }
  // What j and J switch among, also when none shows at first (--no-subs, --sid no).
  std::vector<SubtitleTrackRef> tracks;
  if (!info.still && has_own_subtitles) tracks = subtitle_tracks(request.input, args.sub_file);
  if (!info.still && (subtitles || !tracks.empty())) {
    options.subtitle_tracks = std::move(tracks);
    options.sub_stereo = sub_stereo;
    options.sub_depth = parse_sub_parallax(args.sub_parallax);
    if (!args.sub_parallax && record.sub_parallax && std::abs(*record.sub_parallax) <= max_sub_parallax_percent) {
      options.sub_depth = {false, *record.sub_parallax};
      if (!args.quiet && subtitles)
        fmt::print(stderr, "nelf: subtitle depth {:g} % as last time (--sub-parallax overrides)\n",
                   *record.sub_parallax);
    }
    options.subtitles = std::move(subtitles);
  }
  if (options.start_s && !info.seekable)
    throw UserError(
        fmt::format("{}: cannot start at {:g} s: the input cannot seek", printable(request.input), *options.start_s),
        2);

  PlayResult result = play(display(), *source, options, &interrupt_requested);
  fmt::print(stderr, "nelf: {}\n", play_summary(result));

  if (key) {
    WatchLaterRecord left = record;
    // Stopped before the end: resume there next time; played to the end or left for another file:
    // the next time starts at the beginning, as mpv's.
    const bool stopped =
        result.end == PlayEnd::quit_key || result.end == PlayEnd::window_closed || result.end == PlayEnd::interrupted;
    left.position_s.reset();
    if (args.resume && stopped && !info.still && result.position_s && *result.position_s > 0)
      left.position_s = result.position_s;
    const bool swapped = request.swap_eyes != result.eyes_swapped;
    if (swapped || record.swap_eyes) left.swap_eyes = swapped;
    // A pair's second file is given each time (--right): only a one-file layout is remembered.
    if (common.layout && *common.layout != StereoLayout::pair) left.layout = args.layout;
    // The depth the subtitles were left at, when it is not the default (given or set by keys). Auto
    // is asked for each time: the fixed depth remembered before stays for a play without it.
    if (result.sub_depth && !result.sub_depth->follows_content)
      left.sub_parallax =
          result.sub_depth->percent != 0 ? std::optional<double>(result.sub_depth->percent) : std::nullopt;
    watch_later.save(*key, left, warn);
  }
  return result;
}

}  // namespace

void use_key_rebindings(KeyRebindings rebindings) { rebound_keys() = std::move(rebindings); }

PlayEnd play_input(const PlayArgs& args, SourceRequest request) {
  const std::string input = request.input;
  return play_inputs(args, request, {input});
}

PlayEnd play_inputs(const PlayArgs& args, const SourceRequest& base, const std::vector<std::string>& inputs) {
  quiet_ffmpeg_logs(true);
  // Off screen, play renders headless like convert, on the GPU --gpu picks.
  if (args.output != "offscreen") refuse_gpu_for_live_output(args.gpu, "play");
  CommonOptions common = parse_common_options(args, false);
  parse_track_number(args.aid, "--aid");  // a bad --aid is said before any input opens
  try {
    display_driver(args.output);
  } catch (const std::invalid_argument& e) {
    throw UserError(e.what(), 2);
  }
  if (!args.monitor.empty() && args.output != "fullscreen")
    throw UserError("--monitor chooses the monitor for --output fullscreen", 2);
  if (!args.connector.empty() && args.output != "kms")
    throw UserError("--connector chooses the HDMI connector for --output kms", 2);
  if (args.start && !(*args.start >= 0)) throw UserError("--start must be 0 or more seconds", 2);
  if (args.image_duration && !(*args.image_duration > 0))
    throw UserError("--image-duration must be more than 0 seconds", 2);
  if (args.no_subs && !args.sub_file.empty()) throw UserError("--no-subs and --sub-file contradict each other", 2);
  if (args.no_subs && args.sub_parallax) throw UserError("--sub-parallax does nothing with --no-subs", 2);
  if (args.no_subs && !args.sub_stereo.empty()) throw UserError("--sub-stereo does nothing with --no-subs", 2);
  parse_sub_parallax(args.sub_parallax);  // out of range: said before anything opens
  parse_sub_stereo(args.sub_stereo);
  parse_track_number(args.sid, "--sid");
  const std::vector<std::string> entries = expand_playlist(inputs, warn);
  if (entries.size() > 1 && !args.right.empty())
    throw UserError("--right gives the right view of one input; play the pairs one at a time", 2);

  // Before the input opens: Ctrl-C also ends a wait for a window that is not there yet.
  InterruptGuard guard;
  SourceRequest request = base;
  if (!request.stop) request.stop = &interrupt_requested;  // nelf run gives its own, which covers this one
  request.quiet = args.quiet;
  request.allow_network = args.allow_network;
  request.device_options = parse_device_options(args, entries);
  request.max_pixels = args.max_pixels;
  const WatchLater watch_later(args.remember ? xdg_state_home() : std::filesystem::path());

  const bool keys_from_stdin = std::none_of(entries.begin(), entries.end(), reads_stdin);
  std::unique_ptr<Display> display;
  const std::function<Display&()> open_display = [&]() -> Display& {
    if (!display) {
      display = open_live_display({args.output, args.monitor, args.connector, fmt::format("nelf: {}", entries.front()),
                                   args.gpu, keys_from_stdin},
                                  common.profile, common.signal);
      if (!args.quiet) fmt::print(stderr, "nelf: playing on {}\n", printable(display->description()));
    }
    return *display;
  };

  // One socket for the whole playlist, before anything opens: a bad path stops play at once.
  const std::shared_ptr<playback::IpcServer> ipc =
      args.input_ipc_server.empty() ? nullptr : std::make_shared<playback::IpcServer>(args.input_ipc_server);
  PlayEnd end = PlayEnd::end_of_file;
  std::size_t played = 0;
  bool forward = true;
  for (std::size_t index = 0; index < entries.size();) {
    request.input = entries[index];
    try {
      end = play_entry(args, common, open_display, request, watch_later, index, entries.size(), ipc).end;
      ++played;
    } catch (const UserError& e) {
      // One file is the whole command: its error is play's. In a playlist it is skipped.
      if (entries.size() == 1 || interrupt_requested) throw;
      fmt::print(stderr, "nelf: skipped: {}\n", printable(e.what()));
      end = forward ? PlayEnd::next_file : PlayEnd::previous_file;
      if (!forward && index == 0) end = PlayEnd::next_file;
    }
    if (end == PlayEnd::interrupted) throw UserError("interrupted", 130);
    if (end == PlayEnd::quit_key || end == PlayEnd::window_closed) break;
    forward = end != PlayEnd::previous_file;
    if (forward)
      ++index;
    else
      --index;
  }
  if (played == 0) throw UserError(fmt::format("none of the {} inputs could be played", entries.size()), 1);
  return end;
}

void add_play_options(CLI::App& cmd, PlayArgs& args) {
  add_common_options(cmd, args, false);
  cmd.add_option("--output", args.output, fmt::format("Where to show it: {}", display_driver_help()))
      ->capture_default_str();
  cmd.add_option("--monitor", args.monitor, "fullscreen: the monitor (default: the one named like HMZ)");
  cmd.add_option("--connector", args.connector, "kms: the connector, e.g. HDMI-A-1 (default: the first with 3D)");
  cmd.add_flag("--no-audio", args.no_audio, "Play without sound (the system clock paces the video)");
  cmd.add_flag("--quiet", args.quiet, "Only warnings and the summary line at exit");
  cmd.add_option("--log-frames", args.log_frames,
                 "Diagnostics: write a CSV line per presented refresh (pts, clock, audio clock, counters)");
  cmd.add_option("--input-ipc-server", args.input_ipc_server,
                 "Remote control: mpv's JSON IPC on this Unix socket (owner-only; removed at exit)");
}

namespace {

// A file's sound: play's own (a game's window has none to choose or set).
void add_sound_options(CLI::App& cmd, PlayArgs& args) {
  cmd.add_option("--aid", args.aid, "Audio track: its number (1 = the file's first audio stream), auto or no")
      ->capture_default_str();
  cmd.add_option("--alang", args.alang, "Audio track by language, first match wins: eng,ger (ISO 639-2 as tagged)")
      ->delimiter(',');
  cmd.add_option("--volume", args.volume, "Volume 0 to 130 (100: as decoded; keys 9 0 / *)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 130.0));
  cmd.add_flag("--mute", args.mute, "Start muted (key m)");
}

}  // namespace

void add_play_command(CLI::App& app) {
  auto args = std::make_shared<PlayArgs>();
  auto* cmd = app.add_subcommand("play",
                                 "Watch stereo videos and photos on the display (HMD over HDMI, or a preview "
                                 "window)");
  cmd->add_option("input", args->inputs,
                  "Stereo images or videos (side-by-side, top-bottom, frame-packed, JPS, MPO, ...), folders of them, "
                  ".m3u playlists, or a live window (x11:window=TITLE); several play one after the other")
      ->required();
  add_play_options(*cmd, *args);
  cmd->add_option("--start", args->start, "Start each video at this time (seconds; not photos)");
  cmd->add_option("--image-duration", args->image_duration,
                  "Show each photo this many seconds, then the next (default: until q or the next-file key)");
  cmd->add_flag("--no-resume", args->no_resume, "Start from the beginning, not where the file was stopped last time");
  add_sound_options(*cmd, *args);
  args->subtitles = true;
  cmd->add_option("--sub-file", args->sub_file,
                  "Subtitles from this file (SRT, ASS/SSA, WebVTT, PGS .sup, VobSub .idx, ...; default: "
                  "INPUT.srt/.ass/.vtt/.sup/.idx beside the input, else the input's first subtitle track)");
  cmd->add_flag("--no-subs", args->no_subs, "Show no subtitles (as --sid no)");
  cmd->add_option("--sid", args->sid,
                  "Subtitle track: its number (1 = the file's first subtitle stream, or --sub-file's), auto or no")
      ->capture_default_str();
  cmd->add_option("--slang", args->slang, "Subtitle track by language, first match wins: eng,ger (as tagged)")
      ->delimiter(',');
  cmd->add_option("--sub-parallax", args->sub_parallax,
                  "The subtitles' depth in percent of the view width (positive = in front of the screen; default 0), "
                  "or auto: just in front of the picture beneath them");
  cmd->add_option("--sub-stereo", args->sub_stereo,
                  "Bitmap subtitles (PGS, DVB, VobSub) authored per eye: sbs (left eye's in the left half) or tab "
                  "(left eye's on top)");
  cmd->callback([args] {
    args->resume = !args->no_resume;
    args->remember = true;
    SourceRequest request;
    play_inputs(*args, request, args->inputs);
  });
}

}  // namespace nelf::app
