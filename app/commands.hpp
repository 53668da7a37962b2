#pragma once
// Each `nelf` subcommand lives in its own app/cmd_*.cpp and registers itself here.
#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>

#include "compositor/compositor.hpp"
#include "compositor/profile.hpp"
#include "hmz_output/image_sink.hpp"
#include "hmz_output/signal.hpp"
#include "inputs/stereo_layout.hpp"

namespace nelf::app {

// A problem with how nelf was invoked or with its input; main() prints what() as one line and
// exits with `status` (2 for bad arguments or profiles, 1 for failed jobs).
class UserError : public std::runtime_error {
 public:
  explicit UserError(const std::string& message, int status = 1) : std::runtime_error(message), status_(status) {}
  int status() const { return status_; }

 private:
  int status_;
};

// The --layout option of convert and simulate: "auto" (nullopt: detect) or a layout name.
// Throws UserError (status 2) naming the accepted values.
std::optional<StereoLayout> parse_layout_option(const std::string& name);

// The signal named `name` (--signal), or the profile's output.signal when `name` is empty.
// Throws UserError (status 2) naming the signals there are.
Signal resolve_signal(const Profile& profile, const std::string& name);

// The stills path of convert (also calibrate --pattern): composes `views` with the GL compositor,
// packs both eyes into `signal`'s frame and writes it to `output` (nothing half-written). Throws
// UserError (status 1) when the file cannot be written.
void write_packed_still(const StereoPair& views, const Profile& profile, const Signal& signal,
                        const CompositorOptions& options, const std::string& output, const ImageWriteOptions& write);

// Adds a subcommand to `app`. The callback it installs is run after parsing; it may throw.
using CommandRegistrar = void (*)(CLI::App& app);

void add_profiles_command(CLI::App& app);
void add_design_command(CLI::App& app);
void add_convert_command(CLI::App& app);
void add_probe_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);

}  // namespace nelf::app
