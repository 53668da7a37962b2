#pragma once
// A private X server for the window tests (DESIGN.md §9): Xvfb picks a free display number itself
// (-displayfd), so tests running in parallel never collide and need no xvfb-run wrapper.
#include <sys/types.h>
#include <string>

namespace nelf::test {

class XvfbServer {
 public:
  // Starts `Xvfb -displayfd FD -screen 0 WIDTHxHEIGHTx24 -nolisten tcp -noreset` and waits (up to
  // `timeout_seconds`) until it reports its display number, i.e. accepts connections.
  // Throws std::runtime_error when Xvfb is missing, exits or does not become ready.
  explicit XvfbServer(int width = 1920, int height = 1600, double timeout_seconds = 10.0);
  // Kills the server (SIGTERM, then SIGKILL after a second) and reaps it.
  ~XvfbServer();
  XvfbServer(const XvfbServer&) = delete;
  XvfbServer& operator=(const XvfbServer&) = delete;

  // Kills the server at once (SIGKILL), as when an X session ends under a running program.
  void kill_now();

  // Whether the server process is still alive (a test that lost its windows says which side went).
  bool running() const;

  // ":N", for setenv("DISPLAY", …) or a child's environment.
  const std::string& display_name() const { return display_name_; }

 private:
  pid_t pid_ = -1;
  std::string display_name_;
};

// Sets DISPLAY for this process while alive; restores the previous value (or unsets it) after.
class ScopedDisplay {
 public:
  explicit ScopedDisplay(const std::string& display);  // "" unsets DISPLAY
  ~ScopedDisplay();
  ScopedDisplay(const ScopedDisplay&) = delete;
  ScopedDisplay& operator=(const ScopedDisplay&) = delete;

 private:
  bool had_previous_ = false;
  std::string previous_;
};

}  // namespace nelf::test
