#pragma once
// Each `nelf` subcommand lives in its own app/cmd_*.cpp and registers itself here.
#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "compositor/compositor.hpp"
#include "core/pixel_limit.hpp"
#include "core/user_error.hpp"
#include "hmz_output/image_sink.hpp"
#include "hmz_output/signal.hpp"
#include "inputs/stereo_layout.hpp"
#include "inputs/subtitle_track.hpp"
#include "optics/profile.hpp"
#include "player/subtitle_depth.hpp"

namespace nelf::app {

// See core/user_error.hpp: main() prints what() as one line and exits with status().
using nelf::UserError;

// The --layout option of convert and simulate: "auto" (nullopt: detect) or a layout name.
// Throws UserError (status 2) naming the accepted values.
std::optional<StereoLayout> parse_layout_option(const std::string& name);

// The whole of `text` as a finite number (std::from_chars: no leading '+' or spaces); `ok` says
// whether it was one.
double parse_number(std::string_view text, bool& ok);

// --sub-parallax of play and convert --burn-subs: percent of the view width (unset: 0), or auto
// (just in front of the content beneath). Throws UserError (status 2) for anything else and beyond
// ±10 %, where the two copies no longer fuse into one.
SubtitleDepth parse_sub_parallax(const std::optional<std::string>& parallax);

// --sub-stereo of play and convert --burn-subs: "" (flat), sbs or tab. Throws UserError (status
// 2) naming the accepted values.
SubtitleStereo parse_sub_stereo(const std::string& value);

// --aid and --sid: N (the N-th track of its kind, from 1), auto or no; nullopt for auto and no.
// Throws UserError (status 2) naming `option` otherwise.
std::optional<int> parse_track_number(const std::string& value, const std::string& option);

// The input, layout and rendering options that convert and play share (one parser, one wording).
struct CommonArgs {
  std::string input;
  std::string profile = "hmz-t1";
  std::string layout = "auto";
  std::string right;
  bool swap_eyes = false;
  std::string signal;  // empty = the profile's output.signal
  int fsaa = 1;
  std::string depth = "off";  // --depth: off, auto or estimate
  std::optional<int> gpu;
  bool allow_network = false;
  std::int64_t max_pixels = kDefaultMaxPixels;
  bool no_defect_compensation = false;
  std::vector<std::string> device_options;  // --device-option KEY=VALUE, for v4l2: and device: inputs
};

// CommonArgs checked before any input is read: layout, antialiasing, device, profile and signal.
struct CommonOptions {
  std::optional<StereoLayout> layout;
  CompositorOptions compositor;
  Profile profile;
  Signal signal;
};

// Registers INPUT (positional, unless !with_input) and the CommonArgs options on `cmd`.
void add_common_options(CLI::App& cmd, CommonArgs& args, bool with_input = true);
// Registers INPUT alone (play registers it before its options, run has none).
void add_input_option(CLI::App& cmd, CommonArgs& args);
// Registers --no-defect-compensation (shared by convert, play and calibrate: one wording).
void add_defect_compensation_option(CLI::App& cmd, bool& no_defect_compensation);
// Registers --depth (shared by convert, play and simulate: one wording), and the mode it names.
// Throws UserError (status 2) naming the modes there are.
void add_depth_option(CLI::App& cmd, std::string& depth);
DepthMode parse_depth_option(const std::string& depth);
// Registers --max-pixels (shared by convert, play, probe and simulate: one wording).
void add_max_pixels_option(CLI::App& cmd, std::int64_t& max_pixels);
// Throws UserError (status 2) for contradictory options and unknown signals, ProfileError for bad
// profiles. `still`: the input is a still image (refuses layout alt).
CommonOptions parse_common_options(const CommonArgs& args, bool still);

// --device-option KEY=VALUE, each split; when one of `inputs` is no capture device (v4l2:,
// device:), or without '=', a UserError (status 2).
std::vector<std::pair<std::string, std::string>> parse_device_options(const CommonArgs& args,
                                                                      const std::vector<std::string>& inputs);

// --gpu picks the EGL device of headless rendering; a live output renders on its display's own GPU
// (a GLX context, or the DRM card of kms), so there the option is refused rather than ignored.
void refuse_gpu_for_live_output(const std::optional<int>& gpu, const std::string& command);
// The signal named `name` (--signal), or the profile's output.signal when `name` is empty.
// Throws UserError (status 2) naming the signals there are.
Signal resolve_signal(const Profile& profile, const std::string& name);

// The packed frame of a still (convert, calibrate --pattern): both eyes of `views` composited and
// placed in `signal`'s frame by the compositor facade (FrameCompositor::render_still).
Image packed_still(const StereoPair& views, const Profile& profile, const Signal& signal,
                   const CompositorOptions& options);
// packed_still() written to `output` (nothing half-written). Throws UserError (status 1) when the
// file cannot be written.
void write_packed_still(const StereoPair& views, const Profile& profile, const Signal& signal,
                        const CompositorOptions& options, const std::string& output, const ImageWriteOptions& write);

// Adds a subcommand to `app`. The callback it installs is run after parsing; it may throw.
using CommandRegistrar = void (*)(CLI::App& app);

void add_profiles_command(CLI::App& app);
void add_design_command(CLI::App& app);
void add_convert_command(CLI::App& app);
void add_probe_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_play_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);

// Names `app` nelf and adds --version and every subcommand (app/cli.cpp): the command line that
// main() parses and the man page and completions are generated from.
void build_cli(CLI::App& app);

}  // namespace nelf::app
