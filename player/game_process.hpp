#pragma once
// The game `nelf run` starts: its own process (the user's command line, searched on PATH, with
// nelf's environment), ended with it. A game that ends by itself gives nelf its exit status; one
// still running when nelf stops (q, the window closed, Ctrl-C) is asked to end (SIGTERM) and, if
// it does not within a few seconds, killed, so that nelf never leaves a game running behind it.
#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace nelf {

class GameProcess {
 public:
  // Throws UserError (status 127, as a shell says for a command it cannot find) when the command
  // cannot be started, status 2 when it is empty. `environment`: NAME=VALUE entries set for the
  // game on top of nelf's own (the quad-buffer interposer's LD_PRELOAD).
  explicit GameProcess(const std::vector<std::string>& command, const std::vector<std::string>& environment = {});
  ~GameProcess();  // ends() the game if it still runs
  GameProcess(const GameProcess&) = delete;
  GameProcess& operator=(const GameProcess&) = delete;

  pid_t pid() const { return pid_; }
  const std::string& name() const { return name_; }
  // The game's exit status once it ended (128 + the signal that ended it, as a shell reports it),
  // waiting up to `wait` for it to end; nothing while it still runs.
  std::optional<int> exit_status(std::chrono::milliseconds wait = std::chrono::milliseconds(0));
  // Asks the game to end (SIGTERM), kills it after `grace`, and returns its exit status.
  int end(std::chrono::milliseconds grace = std::chrono::milliseconds(5000));

 private:
  pid_t pid_ = -1;
  std::string name_;
  std::optional<int> status_;
};

}  // namespace nelf
