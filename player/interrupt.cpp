#include "player/interrupt.hpp"

#include <iterator>

namespace nelf {

std::atomic<bool> interrupt_requested{false};

namespace {
extern "C" void on_interrupt(int) { interrupt_requested.store(true); }
}  // namespace

InterruptGuard::InterruptGuard() {
  // A guard inside another (play within nelf run) keeps what the outer one has seen.
  struct sigaction current {};
  sigaction(SIGINT, nullptr, &current);
  if (current.sa_handler != on_interrupt) interrupt_requested.store(false);
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  for (std::size_t i = 0; i < std::size(interrupt_signals); ++i) {
    const int signal = interrupt_signals[i];
    sigaction(signal, nullptr, &previous_[i]);
    // nohup (or a parent) ignoring SIGHUP means "keep running when the terminal goes". SIGINT and
    // SIGQUIT stay handled even when ignored: a shell without job control ignores them for every
    // background command, which must still stop on `kill -INT`.
    if (signal == SIGHUP && previous_[i].sa_handler == SIG_IGN) continue;
    sigaction(signal, &action, nullptr);
  }
}

InterruptGuard::~InterruptGuard() {
  for (std::size_t i = 0; i < std::size(interrupt_signals); ++i)
    sigaction(interrupt_signals[i], &previous_[i], nullptr);
}

}  // namespace nelf
