// `nelf play IN`: watch a stereo video on the HMD (or a preview window) with sound: the player
// engine (player/player) on the display --output picks.
#include <fmt/format.h>

#include <charconv>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>

#include "app/commands.hpp"
#include "app/play_command.hpp"
#include "core/printable.hpp"
#include "core/user_error.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/display_drivers.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/still_source.hpp"
#include "inputs/video_source.hpp"
#include "player/depth_input.hpp"
#include "player/interrupt.hpp"
#include "player/live_display.hpp"
#include "player/play_sound.hpp"
#include "player/player.hpp"

namespace nelf::app {

namespace {

// --aid: N (the N-th audio track), auto (the file's default, or --alang's) or no (no sound).
std::optional<int> audio_track_number(const std::string& aid) {
  if (aid == "auto" || aid == "no") return std::nullopt;
  int number = 0;
  const auto [end, error] = std::from_chars(aid.data(), aid.data() + aid.size(), number);
  if (error != std::errc() || end != aid.data() + aid.size() || number < 1)
    throw UserError(fmt::format("--aid {}: a track number from 1, auto or no", printable(aid)), 2);
  return number;
}

}  // namespace

PlayEnd play_input(const PlayArgs& args, SourceRequest request) {
  quiet_ffmpeg_logs(true);
  // Off screen, play renders headless like convert, on the GPU --gpu picks.
  if (args.output != "offscreen") refuse_gpu_for_live_output(args.gpu, "play");
  CommonOptions common = parse_common_options(args, false);
  const std::optional<int> audio_track = audio_track_number(args.aid);
  try {
    display_driver(args.output);
  } catch (const std::invalid_argument& e) {
    throw UserError(e.what(), 2);
  }
  if (!args.monitor.empty() && args.output != "fullscreen")
    throw UserError("--monitor chooses the monitor for --output fullscreen", 2);
  if (!args.connector.empty() && args.output != "kms")
    throw UserError("--connector chooses the HDMI connector for --output kms", 2);

  // Before the input opens: Ctrl-C also ends a wait for a window that is not there yet.
  InterruptGuard guard;
  request.stop = &interrupt_requested;
  request.right = args.right;
  request.layout = args.right.empty() ? common.layout : StereoLayout::pair;
  request.swap_eyes = args.swap_eyes;
  request.quiet = args.quiet;
  request.allow_network = args.allow_network;
  request.max_pixels = args.max_pixels;
  const auto source = open_source_for_depth(request, common.compositor.depth, common.profile);

  PlayerOptions options;
  options.profile = common.profile;
  options.signal = common.signal;
  options.compositor = common.compositor;
  options.audio = !args.no_audio && args.aid != "no";
  options.audio_track = audio_track;
  if (args.aid == "no") options.no_audio_reason = "--aid no";
  options.audio_languages = args.alang;
  options.volume = args.volume;
  options.mute = args.mute;
  // A track that is not there is said before anything plays.
  if (options.audio) playback::choose_audio_track(source->audio_tracks(), options.audio_track, options.audio_languages);
  options.log_frames = args.log_frames;
  options.quiet = args.quiet;

  const auto display =
      open_live_display({args.output, args.monitor, args.connector, fmt::format("nelf: {}", request.input), args.gpu},
                        common.profile, common.signal);
  if (!args.quiet) fmt::print(stderr, "nelf: playing on {}\n", printable(display->description()));

  const PlayResult result = play(*display, *source, options, &interrupt_requested);
  fmt::print(stderr, "nelf: {}\n", play_summary(result));
  if (result.end == PlayEnd::interrupted) throw UserError("interrupted", 130);
  return result.end;
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
  auto* cmd = app.add_subcommand("play", "Watch a stereo video on the display (HMD over HDMI, or a preview window)");
  add_input_option(*cmd, *args);
  add_play_options(*cmd, *args);
  add_sound_options(*cmd, *args);
  cmd->callback([args] {
    SourceRequest request;
    request.input = args->input;
    play_input(*args, request);
  });
}

}  // namespace nelf::app
