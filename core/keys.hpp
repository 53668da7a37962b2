#pragma once
// Key presses as the outputs report them (a window, a terminal under KMS) and the player and
// calibration act on them.

namespace nelf {

// One key press, layout-aware: printable keys arrive as the character typed ('+', '[', 'S'),
// the others by name.
struct KeyPress {
  enum class Named { none, space, left, right, up, down, page_up, page_down, escape, enter, tab, backspace };
  Named named = Named::none;
  char32_t character = 0;  // set when named == Named::none
  bool shift = false;
  bool ctrl = false;
  bool alt = false;

  static KeyPress of(Named n) { return KeyPress{n, 0, false, false, false}; }
  static KeyPress of(char32_t c) { return KeyPress{Named::none, c, false, false, false}; }
  bool is(Named n) const { return named == n; }
  bool is(char32_t c) const { return named == Named::none && character == c; }
};

}  // namespace nelf
