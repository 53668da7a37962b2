#pragma once
// Keys → commands for `nelf play`, `nelf calibrate` and `nelf calibrate --defects`: one table (key_bindings.cpp), from
// which the loops take what a key press means, and the on-screen and terminal help (h) and the README's key tables are
// made, so that none of them can drift from what the keys do.
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/keys.hpp"

namespace nelf {

// calibrate: the test patterns through the lenses; defects: the flat fields of --defects.
enum class KeyScope { play, calibrate, defects };

enum class Command {
  quit,
  help,
  // play
  pause,
  seek_back_10s,
  seek_forward_10s,
  seek_back_60s,
  seek_forward_60s,
  screen_farther,
  screen_nearer,
  ipd_narrower,
  ipd_wider,
  swap_eyes,
  calibration_grid,
  fullscreen,
  next_file,
  previous_file,
  next_audio_track,
  toggle_subtitles,
  next_subtitle_track,
  previous_subtitle_track,
  subtitles_nearer,
  subtitles_farther,
  screenshot,
  screenshot_views,
  volume_down,
  volume_up,
  mute,
  show_progress,
  keep_progress,
  // calibrate
  next_eye,
  shift_left,
  shift_right,
  shift_up,
  shift_down,
  rotate_less,
  rotate_more,
  pitch_less,
  pitch_more,
  gap_less,
  gap_more,
  prescription_less,
  prescription_more,
  pattern_stripes,
  pattern_grid,
  pattern_snellen,
  pattern_white,
  save,
  // defects (Tab: next_eye)
  cursor_left,
  cursor_right,
  cursor_up,
  cursor_down,
  field_next,
  field_black,
  field_white,
  field_red,
  field_green,
  field_blue,
  mark_dead,
  mark_stuck,
  unmark,
  next_defect,
  status_line,
};

// One line of help: the keys it names and what each does.
struct KeyBinding {
  KeyScope scope;
  std::vector<std::pair<KeyPress, Command>> keys;
  std::string_view label;           // the keys as the help says them, e.g. "r R", "arrows"
  std::string_view markdown_label;  // the same for the README, e.g. "`r` / `R`"
  std::string_view help;            // what they do, short: on screen and in the terminal
  std::string_view detail;          // more for the README ("" for none)
  std::string_view profile_key;     // calibrate: the profile key it changes ("" for none)
};

const std::vector<KeyBinding>& key_bindings();

// A key of `nelf play` given another command by the user (the configuration file's [keys]):
// nullopt unbinds it ("ignore", as mpv's input.conf says).
struct KeyRebinding {
  KeyPress key;
  std::optional<Command> command;
};
using KeyRebindings = std::vector<KeyRebinding>;

// What `key` means in `scope`, after `rebindings` (which change play's keys only). A printable key
// matches with Shift (it is the character typed) but not with Ctrl or Alt; a named key (arrows,
// Tab, …) matches with any modifier.
std::optional<Command> command_for(KeyScope scope, const KeyPress& key, const KeyRebindings& rebindings = {});

// "label: help", one line per row of `scope`; with `rebindings`, a row names the keys it still has
// (none: it is left out) and each rebound key has a line of its own, so that h shows what the keys do.
std::vector<std::string> key_help(KeyScope scope, const KeyRebindings& rebindings = {});

// The name of play's command `command` in the configuration file ("swap-eyes"); "" for the
// commands that are not play's.
std::string_view command_name(Command command);
// Play's command named `name`; nullopt for no such name.
std::optional<Command> command_named(std::string_view name);
// Every name command_named() knows, in the table's order.
std::vector<std::string> play_command_names();

// The key a configuration file names: one character ("x", "+", "é") or a key name as mpv's
// input.conf writes it, any case (SPACE, LEFT, RIGHT, UP, DOWN, PGUP, PGDWN, ESC, ENTER, TAB, BS);
// nullopt for anything else.
std::optional<KeyPress> parse_key_name(std::string_view name);
// The name the help gives `key` ("x", "space", "left", "Esc").
std::string key_name(const KeyPress& key);

// The README's table of `scope`'s keys (play, defects: key | does; calibrate: key | changes | profile key).
std::string key_table_markdown(KeyScope scope);

}  // namespace nelf
