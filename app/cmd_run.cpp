// `nelf run [play options] -- GAME [ARGS...]`: starts a stereo game and shows it on the HMD. An
// OpenGL game gets nelf's interposer (LD_PRELOAD), and what it swaps comes from there (the
// glx-stereo: source): a quad-buffer game's two eyes, or the picture of a game that draws both
// eyes into one, its layout detected as for a file or given by --layout. A game that swaps no
// OpenGL buffer through GLX (or a window --window names) has its window captured live instead
// (the x11: source; its _NET_WM_PID's window). Either is played with play's options. nelf ends
// when the game does, with the game's exit status; quitting nelf (q, closing its window, Ctrl-C)
// ends the game too.
#include <fmt/format.h>

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "app/commands.hpp"
#include "app/freed_memory.hpp"
#include "app/play_command.hpp"
#include "core/printable.hpp"
#include "inputs/glx_stereo_protocol.hpp"
#include "inputs/glx_stereo_source.hpp"
#include "player/game_process.hpp"
#include "player/interrupt.hpp"

namespace nelf::app {
namespace {

struct RunArgs : PlayArgs {
  std::string window;
  double wait_s = 60;
  std::vector<std::string> game;
};

// Whether the game ended (without reaping it: GameProcess does that on nelf's thread).
bool game_ended(pid_t pid) {
  siginfo_t info{};
  return waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) != 0 || info.si_pid == pid;
}

// Where this run listens for the interposer: the user's runtime folder, else the temporary one.
std::string interposer_socket_path() {
  const char* runtime = std::getenv("XDG_RUNTIME_DIR");
  const std::filesystem::path folder =
      runtime && *runtime && std::filesystem::is_directory(runtime) ? runtime : std::filesystem::temp_directory_path();
  return (folder / fmt::format("nelf-run-{}.sock", getpid())).string();
}

// How long a game may take to swap its first OpenGL frame before nelf stops expecting its eyes
// from the interposer and waits for its window alone.
constexpr double kFirstSwapWait_s = 5;

void run_game(const RunArgs& args, const std::vector<std::string>& command) {
  if (args.wait_s <= 0) throw UserError("--wait must be more than 0 seconds", 2);
  // From the start: a Ctrl-C while the game starts or between its windows ends both too.
  InterruptGuard guard;
  // nelf's interposer goes into the game and hands over both eyes, or the one picture, at each
  // swap (inputs/glx_stereo_source.hpp): no trip through the X server, and vsync to nelf's
  // refreshes for either.
  const std::string socket = interposer_socket_path();
  std::string preload = glx_stereo_library_path();
  if (const char* before = std::getenv("LD_PRELOAD"); before && *before) preload += std::string(":") + before;
  GameProcess game(command, {"LD_PRELOAD=" + preload, std::string(glx_stereo::kSocketVariable) + "=" + socket,
                             "GLIBC_TUNABLES=" + freed_memory_tunables(std::getenv("GLIBC_TUNABLES"))});
  // --window names a window to capture: its picture, whoever draws it, through the X server.
  bool from_interposer = args.window.empty();
  // Stops waiting for the first swap when the user interrupts or the game ends without one.
  std::atomic<bool> stop_waiting{false};
  std::jthread watcher([&](std::stop_token stop) {
    while (!stop.stop_requested() && !stop_waiting) {
      if (interrupt_requested || game_ended(game.pid())) stop_waiting = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  // Games close their window and open another (a splash or launcher first, a new window for a new
  // video mode): while the game runs, nelf plays each window it opens.
  for (bool first = true;; first = false) {
    PlayEnd end = PlayEnd::end_of_file;
    try {
      if (from_interposer) {
        SourceRequest request;
        request.stop = &stop_waiting;
        request.input = fmt::format("glx-stereo:wait={:g},socket={}", kFirstSwapWait_s, socket);
        try {
          end = play_input(args, request);  // --layout: for a game that draws one picture
        } catch (const GameDidNotSwap&) {
          from_interposer = false;
          if (!args.quiet)
            fmt::print(stderr, "nelf: {} swapped no OpenGL frame in {:g} s: waiting for its window\n",
                       printable(game.name()), kFirstSwapWait_s);
        } catch (const UserError& e) {
          if (e.status() != 130 || interrupt_requested) throw;
          from_interposer = false;  // the game ended while nelf waited: its status follows
        }
      }
      if (!from_interposer) {
        SourceRequest request;
        request.stop = &interrupt_requested;
        // window= takes the rest of the spec (a title may hold commas), so it comes last.
        request.input = args.window.empty() ? fmt::format("x11:pid={},wait={:g}", game.pid(), args.wait_s)
                                            : fmt::format("x11:wait={:g},window={}", args.wait_s, args.window);
        end = play_input(args, request);
      }
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
                  "Capture this window (a part of its title) through the X server instead of reading what the "
                  "game swaps (default: what an OpenGL game swaps, else the window its process opens)");
  cmd->add_option("--wait", args->wait_s, "How long to wait for the game's window, in seconds")->capture_default_str();
  // After `--`, everything is the game's command line, its options included.
  cmd->add_option("game", args->game, "The game and its arguments, after --")->expected(-1);
  cmd->callback([args] { run_game(*args, args->game); });
}

}  // namespace nelf::app
