#pragma once
// Each `nelf` subcommand lives in its own app/cmd_*.cpp and registers itself here.
#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>

#include "inputs/stereo_layout.hpp"
#include "inputs/user_error.hpp"

namespace nelf::app {

// See inputs/user_error.hpp: main() prints what() as one line and exits with status().
using nelf::UserError;

// The --layout option of convert and simulate: "auto" (nullopt: detect) or a layout name.
// Throws UserError (status 2) naming the accepted values.
std::optional<StereoLayout> parse_layout_option(const std::string& name);

// Adds a subcommand to `app`. The callback it installs is run after parsing; it may throw.
using CommandRegistrar = void (*)(CLI::App& app);

void add_profiles_command(CLI::App& app);
void add_design_command(CLI::App& app);
void add_convert_command(CLI::App& app);
void add_probe_command(CLI::App& app);
void add_simulate_command(CLI::App& app);

}  // namespace nelf::app
