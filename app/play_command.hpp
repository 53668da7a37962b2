#pragma once
// What `nelf play` and `nelf run` share: the options of watching on a display and the run of the
// player on one input (`run` plays its game's window with them).
#include <CLI/CLI.hpp>
#include <string>

#include "app/commands.hpp"
#include "inputs/source.hpp"
#include "player/player.hpp"

namespace nelf::app {

struct PlayArgs : CommonArgs {
  std::string output = "window";
  std::string monitor;
  std::string connector;
  bool no_audio = false;
  bool quiet = false;
  std::string log_frames;
  std::string input_ipc_server;
};

// The CommonArgs options (without INPUT) and play's own, on `cmd`.
void add_play_options(CLI::App& cmd, PlayArgs& args);

// Plays `request` (its input, with the layout, eyes, limits and depth of `args`) on the output
// `args` names until it ends, the user quits or Ctrl-C; prints the summary line. Throws UserError
// (status 130 when interrupted) as play reports it.
PlayEnd play_input(const PlayArgs& args, SourceRequest request);

// The keys play_input() plays with, rebound (the configuration file's [keys]; main() reads it
// before the command line, so that play and run get the same keys).
void use_key_rebindings(KeyRebindings rebindings);

}  // namespace nelf::app
