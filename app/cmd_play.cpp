// `nelf play IN`: watch a stereo video on the HMD (or a preview window) with sound: the player
// engine (player/player) on the display --output picks.
#include <fmt/format.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <utility>

#include "app/commands.hpp"
#include "app/play_command.hpp"
#include "core/printable.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/display_drivers.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/still_source.hpp"
#include "inputs/video_source.hpp"
#include "player/depth_input.hpp"
#include "player/interrupt.hpp"
#include "player/live_display.hpp"
#include "player/player.hpp"

namespace nelf::app {

namespace {
KeyRebindings& rebound_keys() {
  static KeyRebindings keys;
  return keys;
}
}  // namespace

void use_key_rebindings(KeyRebindings rebindings) { rebound_keys() = std::move(rebindings); }

PlayEnd play_input(const PlayArgs& args, SourceRequest request) {
  quiet_ffmpeg_logs(true);
  // Off screen, play renders headless like convert, on the GPU --gpu picks.
  if (args.output != "offscreen") refuse_gpu_for_live_output(args.gpu, "play");
  CommonOptions common = parse_common_options(args, false);
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
  options.audio = !args.no_audio;
  options.log_frames = args.log_frames;
  options.quiet = args.quiet;
  options.key_rebindings = rebound_keys();
  options.ipc_server = args.input_ipc_server;
  options.media_path = request.input;

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
  cmd.add_option("--input-ipc-server", args.input_ipc_server,
                 "Remote control: mpv's JSON IPC on this Unix socket (owner-only; removed at exit)");
}

void add_play_command(CLI::App& app) {
  auto args = std::make_shared<PlayArgs>();
  auto* cmd = app.add_subcommand("play", "Watch a stereo video on the display (HMD over HDMI, or a preview window)");
  add_input_option(*cmd, *args);
  add_play_options(*cmd, *args);
  cmd->callback([args] {
    SourceRequest request;
    request.input = args->input;
    play_input(*args, request);
  });
}

}  // namespace nelf::app
