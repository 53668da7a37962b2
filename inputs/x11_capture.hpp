#pragma once
// Reading an X11 window (or the whole screen) as it changes, for the `x11:` source: XComposite
// keeps the window's contents off screen, so what covers it does not matter and no cursor is in
// them; XDamage says when they changed (a new frame, not a poll); XShm reads them through shared
// memory rather than the socket (XGetImage where the server has no MIT-SHM). The window is found
// by a substring of its title, by its id, or by the process that made it (`nelf run`).
#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "inputs/live_capture.hpp"

namespace nelf {

// What `x11:[display=:N,][fps=N,][wait=S,][window=TITLE|window-id=0x…|pid=N]` names. Nothing: the
// screen.
struct X11CaptureSpec {
  std::string display;                     // empty: $DISPLAY
  std::optional<std::string> title;        // a substring of the window's title
  std::optional<unsigned long> window_id;  // an X window id (hex with 0x, or decimal)
  std::optional<pid_t> pid;                // the window of this process (_NET_WM_PID)
  double fps = 60.0;                       // the most frames a second that are read
  double wait_s = 0.0;                     // how long to wait for the window to appear (pid=: 60 s)
};

bool is_x11_capture_spec(std::string_view input);
// Throws UserError (status 2) for unknown keys and bad values.
X11CaptureSpec parse_x11_capture_spec(const std::string& input);

class X11Capture final : public LiveCapture {
 public:
  // Connects and finds the window; waits up to spec.wait_s for a window that is not there (yet)
  // or not mapped. Throws UserError (status 1) when the display cannot be opened, the window is not
  // found, or the server lacks Composite or Damage; status 2 when a title matches several windows
  // (they are listed, to choose one by id).
  // `stop` (may be null), set from another thread, ends the wait with status 130.
  explicit X11Capture(const X11CaptureSpec& spec, const std::atomic<bool>* stop = nullptr);
  ~X11Capture() override;
  X11Capture(const X11Capture&) = delete;
  X11Capture& operator=(const X11Capture&) = delete;

  // The contents now (the first frame), without waiting for a change.
  CapturedImage read() override;
  // Waits up to `wait` for the contents to change, then reads them; nothing when they did not
  // change in that time or the window is gone (closed()). Follows the window's resizes.
  std::optional<CapturedImage> read_when_changed(std::chrono::milliseconds wait) override;
  // The window was destroyed or unmapped (the game ended).
  bool closed() const override;
  // "window 0x1e00002 \"Doom 3\"" or "the screen of :0".
  const std::string& description() const override;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace nelf
