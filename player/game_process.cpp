#include "player/game_process.hpp"

#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <string_view>
#include <thread>

#include "core/printable.hpp"
#include "core/user_error.hpp"

extern char** environ;

namespace nelf {

GameProcess::GameProcess(const std::vector<std::string>& command, const std::vector<std::string>& environment) {
  if (command.empty()) throw UserError("nelf run needs the game to start: nelf run [options] -- GAME [ARGS...]", 2);
  name_ = command.front();
  std::vector<char*> argv;
  for (const std::string& arg : command) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  // The game keeps nelf's process group, so that Ctrl-C in the terminal reaches both, as the
  // user expects of a program started from a shell; nelf's signal handlers are not inherited
  // (posix_spawn resets handled signals to their defaults).
  // nelf ignores SIGPIPE (it reports a closed pipe as an error); a game gets it back.
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGPIPE);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF);
  std::vector<char*> env;
  for (char** e = environ; *e; ++e) {
    const std::string_view entry(*e);
    const auto named = [&](const std::string& set) {
      return entry.substr(0, entry.find('=') + 1) == set.substr(0, set.find('=') + 1);
    };
    if (std::none_of(environment.begin(), environment.end(), named)) env.push_back(*e);
  }
  for (const std::string& entry : environment) env.push_back(const_cast<char*>(entry.c_str()));
  env.push_back(nullptr);
  const int failed = posix_spawnp(&pid_, argv[0], nullptr, &attributes, argv.data(), env.data());
  posix_spawnattr_destroy(&attributes);
  if (failed != 0) {
    pid_ = -1;
    throw UserError(fmt::format("{}: cannot start it: {}", printable(name_), std::strerror(failed)), 127);
  }
}

GameProcess::~GameProcess() {
  if (pid_ > 0 && !status_) end();
}

std::optional<int> GameProcess::exit_status(std::chrono::milliseconds wait) {
  if (status_ || pid_ <= 0) return status_;
  const auto until = std::chrono::steady_clock::now() + wait;
  for (;;) {
    int raw = 0;
    const pid_t done = ::waitpid(pid_, &raw, WNOHANG);
    if (done == pid_) {
      status_ = WIFEXITED(raw) ? WEXITSTATUS(raw) : WIFSIGNALED(raw) ? 128 + WTERMSIG(raw) : 1;
      return status_;
    }
    if (done < 0 && errno != EINTR) {
      status_ = 1;  // not our child any more: nothing to wait for
      return status_;
    }
    if (std::chrono::steady_clock::now() >= until) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

int GameProcess::end(std::chrono::milliseconds grace) {
  if (const std::optional<int> ended = exit_status()) return *ended;
  ::kill(pid_, SIGTERM);
  if (const std::optional<int> ended = exit_status(grace)) return *ended;
  ::kill(pid_, SIGKILL);
  return exit_status(std::chrono::milliseconds(5000)).value_or(128 + SIGKILL);
}

}  // namespace nelf
