#pragma once
// The configuration file, $XDG_CONFIG_HOME/nelf/nelf.toml (~/.config/nelf/nelf.toml): a table per
// command of defaults for its long options ([play] output = "fullscreen"), which the command line
// overrides, and [keys], play's keys rebound as mpv's input.conf does ("x" = "swap-eyes").
#include <CLI/CLI.hpp>
#include <filesystem>
#include <optional>

#include "player/key_bindings.hpp"

namespace nelf::app {

// $XDG_CONFIG_HOME/nelf/nelf.toml, XDG_CONFIG_HOME being ~/.config when unset or empty (the XDG
// base directory specification); nullopt when neither it nor HOME is set.
std::optional<std::filesystem::path> config_file_path();

// Whether `argv` asks to ignore the configuration file (--no-config before any "--"). Read before
// the command line is parsed: the file's defaults must be in place by then.
bool no_config_requested(int argc, const char* const* argv);

// Registers --no-config on every subcommand of `app`, for the help, the man page and completions
// (no_config_requested() is what acts on it).
void add_no_config_flag(CLI::App& app);

// Reads the file at `path`, when there is one, and sets its values as the defaults of the options
// of `app`'s subcommands; returns its [keys]. Throws UserError (status 2) naming the file and line
// for a TOML syntax error, an unknown table, key, key name or command (with the nearest known
// one), or a value the option does not take (with what it takes).
KeyRebindings apply_config_file(CLI::App& app, const std::filesystem::path& path);

}  // namespace nelf::app
