#pragma once
// Keyboard input without a window system (`--output kms` runs from a text console): the terminal
// in raw mode, and a parser from the bytes a terminal sends to KeyPress.
#include <termios.h>

#include <string>
#include <string_view>
#include <vector>

#include "hmz_output/display.hpp"

namespace nelf {

// Turns terminal bytes into key presses: printable characters (UTF-8), space, Enter, Tab,
// Backspace, Ctrl+letter, the arrows and Page Up/Down as CSI (ESC [ A, ESC [ 5 ~) or SS3 (ESC O A)
// sequences with xterm modifiers (ESC [ 1 ; 5 C is Ctrl+Right), Alt+key as ESC key, and Esc alone.
// A read that stops inside an escape sequence keeps its start for the next feed(); a read that
// ends with a lone ESC is the Esc key (terminals write a whole sequence at once).
class TerminalKeyParser {
 public:
  std::vector<KeyPress> feed(std::string_view bytes);
  // True while an incomplete escape sequence waits for more bytes.
  bool pending() const { return !pending_.empty(); }

 private:
  std::string pending_;
};

// Puts a terminal into raw mode (no line buffering, no echo, reads return at once with what is
// there) for its lifetime and restores the saved settings in its destructor. Ctrl+C still raises
// SIGINT (ISIG stays on) so that the player's handler stops it cleanly; Ctrl+Z is disabled, since
// a stopped KMS client would leave the screen frozen and the terminal raw.
//
// Signals: a handler that must exit at once calls restore_terminal_from_signal(), which is
// async-signal-safe (one tcsetattr on the settings saved here); the usual path — the handler sets a
// flag, the loop ends, destructors run — needs nothing more.
class RawTerminal {
 public:
  // Does nothing when `fd` is not a terminal (active() is then false).
  explicit RawTerminal(int fd);
  ~RawTerminal();
  RawTerminal(const RawTerminal&) = delete;
  RawTerminal& operator=(const RawTerminal&) = delete;
  bool active() const { return active_; }

 private:
  int fd_;
  bool active_ = false;
  termios saved_{};
};

// Restores the terminal settings saved by the live RawTerminal, if any. Async-signal-safe.
void restore_terminal_from_signal() noexcept;

// Key presses from a terminal: raw mode while alive, non-blocking reads.
class TerminalKeys {
 public:
  explicit TerminalKeys(int fd);
  bool active() const { return raw_.active(); }
  // The key presses typed since the last call; never blocks. Empty when the fd is not a terminal.
  std::vector<KeyPress> read_available();
  // The terminal hung up (read returned end of file, e.g. the console closed).
  bool hung_up() const { return hung_up_; }

 private:
  int fd_;
  RawTerminal raw_;
  TerminalKeyParser parser_;
  bool hung_up_ = false;
};

}  // namespace nelf
