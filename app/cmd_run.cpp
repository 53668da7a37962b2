// `nelf run [play options] -- GAME [ARGS...]`: starts a stereo game and shows it on the HMD. The
// window the game's process opens (its _NET_WM_PID, or the title --window names) is captured live
// (the x11: source) and played with play's options, its layout detected as for a file or given by
// --layout. nelf ends when the game does, with the game's exit status; quitting nelf (q, closing
// its window, Ctrl-C) ends the game too.
#include <fmt/format.h>

#include <memory>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/play_command.hpp"
#include "core/printable.hpp"
#include "player/game_process.hpp"
#include "player/interrupt.hpp"

namespace nelf::app {
namespace {

struct RunArgs : PlayArgs {
  std::string window;
  double wait_s = 60;
  std::vector<std::string> game;
};

void run_game(const RunArgs& args, const std::vector<std::string>& command) {
  if (args.wait_s <= 0) throw UserError("--wait must be more than 0 seconds", 2);
  // From the start: a Ctrl-C while the game starts or between its windows ends both too.
  InterruptGuard guard;
  GameProcess game(command);
  SourceRequest request;
  request.stop = &interrupt_requested;
  // window= takes the rest of the spec (a title may hold commas), so it comes last.
  request.input = args.window.empty() ? fmt::format("x11:pid={},wait={:g}", game.pid(), args.wait_s)
                                      : fmt::format("x11:wait={:g},window={}", args.wait_s, args.window);
  // Games close their window and open another (a splash or launcher first, a new window for a new
  // video mode): while the game runs, nelf plays each window it opens.
  for (bool first = true;; first = false) {
    PlayEnd end = PlayEnd::end_of_file;
    try {
      end = play_input(args, request);
    } catch (const UserError& e) {
      // A game that failed before it opened a window says why itself; its status is nelf's.
      if (const std::optional<int> status = game.exit_status(); status && *status != 0 && e.status() != 130)
        throw UserError(fmt::format("{} (the game exited with status {})", e.what(), *status), *status);
      if (!first && game.exit_status(std::chrono::milliseconds(1000))) break;  // ended without a new window
      throw;
    }
    if (interrupt_requested) {
      game.end();
      throw UserError("interrupted", 130);
    }
    if (end != PlayEnd::end_of_file) {
      game.end();  // the user stopped watching: the game goes with nelf
      return;
    }
    if (game.exit_status(std::chrono::milliseconds(1000))) break;
    if (!args.quiet) fmt::print(stderr, "nelf: the game's window closed; waiting for its next one\n");
  }
  const int status = game.exit_status().value_or(game.end());
  if (status != 0) throw UserError(fmt::format("{} exited with status {}", printable(game.name()), status), status);
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  auto* cmd = app.add_subcommand(
      "run", "Start a stereo game and play its window on the display: nelf run [options] -- GAME [ARGS...]");
  add_play_options(*cmd, *args);
  cmd->add_option("--window", args->window,
                  "The game's window: a part of its title (default: the window the game's process opens)");
  cmd->add_option("--wait", args->wait_s, "How long to wait for the game's window, in seconds")->capture_default_str();
  // After `--`, everything is the game's command line, its options included.
  cmd->add_option("game", args->game, "The game and its arguments, after --")->expected(-1);
  cmd->callback([args] { run_game(*args, args->game); });
}

}  // namespace nelf::app
