#pragma once
// What `nelf play` and `nelf run` share: the options of watching on a display and the run of the
// player on one input (`run` plays its game's window with them).
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "inputs/source.hpp"
#include "player/player.hpp"

namespace nelf::app {

struct PlayArgs : CommonArgs {
  std::string output = "window";
  std::string monitor;
  std::string connector;
  bool no_audio = false;
  std::string aid = "auto";  // a track number, auto or no
  std::vector<std::string> alang;
  double volume = 100.0;
  bool mute = false;
  bool quiet = false;
  std::string log_frames;
  // play's own (nelf run plays a live window: no playlist, no start, nothing remembered).
  std::vector<std::string> inputs;       // INPUT...: files, folders, .m3u playlists
  std::optional<double> start;           // --start
  std::optional<double> image_duration;  // --image-duration
  bool no_resume = false;                // --no-resume
  bool resume = false;                   // play: on unless --no-resume
  bool remember = false;                 // play: keep each file's position and set-up between runs
  std::string input_ipc_server;
  // play's subtitles (a game has none): --no-subs, --sub-file, --sub-parallax.
  bool subtitles = false;
  bool no_subs = false;
  std::string sub_file;
  std::optional<std::string> sub_parallax;
  std::string sub_stereo;    // --sub-stereo: "" (flat), sbs or tab
  std::string sid = "auto";  // a track number, auto or no
  std::vector<std::string> slang;
};

// The CommonArgs options (without INPUT) and play's own, on `cmd`.
void add_play_options(CLI::App& cmd, PlayArgs& args);

// Plays `request` (its input, with the layout, eyes, limits and depth of `args`) on the output
// `args` names until it ends, the user quits or Ctrl-C; prints the summary line. Throws UserError
// (status 130 when interrupted) as play reports it.
PlayEnd play_input(const PlayArgs& args, SourceRequest request);

// The same for each input of `inputs` in turn on one display, as a playlist: the keys step to the
// next and previous one; an entry that fails is skipped with one line when there are others.
PlayEnd play_inputs(const PlayArgs& args, const SourceRequest& request, const std::vector<std::string>& inputs);

// The keys play_input() plays with, rebound (the configuration file's [keys]; main() reads it
// before the command line, so that play and run get the same keys).
void use_key_rebindings(KeyRebindings rebindings);

}  // namespace nelf::app
