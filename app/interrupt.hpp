#pragma once
// SIGINT/SIGTERM for long-running commands (convert, play): a flag every stage polls instead of
// dying mid-write, so that the command cleans up and exits 130.
#include <atomic>
#include <csignal>

namespace nelf::app {

// Set by SIGINT/SIGTERM while an InterruptGuard is alive.
extern std::atomic<bool> interrupted;

// Installs the handlers for its lifetime (clearing the flag) and restores the previous ones.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction previous_int_ {};
  struct sigaction previous_term_ {};
};

}  // namespace nelf::app
