#pragma once
// The test game (tests/game/) started for a test: its own process with the given arguments, in
// the test's DISPLAY, ended (SIGTERM, then SIGKILL) and reaped when the test is done with it.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace nelf::test {

class TestGame {
 public:
  // `environment`: NAME=VALUE entries set for the game (the quad-buffer interposer's).
  explicit TestGame(const std::vector<std::string>& args, const std::vector<std::string>& environment = {}) {
    std::vector<std::string> all{NELF_TEST_GAME};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_ = fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      for (const std::string& entry : environment) putenv(const_cast<char*>(entry.c_str()));
      execv(argv[0], argv.data());
      _exit(127);
    }
  }
  ~TestGame() {
    if (pid_ <= 0 || exited_) return;
    kill(pid_, SIGTERM);
    for (int i = 0; i < 200 && !wait_exit(std::chrono::milliseconds(10)); ++i) {
    }
    if (!exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  TestGame(const TestGame&) = delete;
  TestGame& operator=(const TestGame&) = delete;

  pid_t pid() const { return pid_; }
  // True once the game has ended (within `wait`); its status in status().
  bool wait_exit(std::chrono::milliseconds wait) {
    const auto until = std::chrono::steady_clock::now() + wait;
    while (!exited_) {
      int raw = 0;
      if (waitpid(pid_, &raw, WNOHANG) == pid_) {
        exited_ = true;
        status_ = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
        break;
      }
      if (std::chrono::steady_clock::now() >= until) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return exited_;
  }
  int status() const { return status_; }

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
  int status_ = -1;
};

// A view's pixel near its bottom edge, below the test game's bars and far from its stamp band, is
// the game's background (0.16, 0.18, 0.24): red, green and blue where they belong, whatever byte
// order the game's pixels were read in. `view`: 8-bit RGBA, top row first.
inline void expect_game_background_below_the_bars(const std::vector<std::uint8_t>& view, int width, int height) {
  const std::size_t at = (static_cast<std::size_t>(height - 2) * width + static_cast<std::size_t>(width / 2)) * 4;
  ASSERT_LT(at + 3, view.size());
  EXPECT_NEAR(view[at + 0], 41, 2);
  EXPECT_NEAR(view[at + 1], 46, 2);
  EXPECT_NEAR(view[at + 2], 61, 2);
}

}  // namespace nelf::test
