#pragma once
// SIGINT, SIGTERM, SIGHUP and SIGQUIT for long-running commands (convert, play): a flag every stage
// polls instead of dying mid-write, so that the command cleans up and exits 130. One status for
// all four, as ffmpeg exits with one status (255) for every signal it stops on: a script checks
// one number for "stopped before the end". A closed terminal (SIGHUP) is such a stop too, except
// under nohup: an ignored SIGHUP stays ignored.
#include <atomic>
#include <csignal>

namespace nelf {

// Set by SIGINT/SIGTERM/SIGHUP/SIGQUIT while an InterruptGuard is alive.
extern std::atomic<bool> interrupt_requested;

// The signals an InterruptGuard turns into `interrupt_requested`.
inline constexpr int interrupt_signals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

// Installs the handlers for its lifetime (clearing the flag, unless it is inside another guard)
// and restores the previous ones.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction previous_[std::size(interrupt_signals)]{};
};

}  // namespace nelf
