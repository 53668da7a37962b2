#include "player/key_bindings.hpp"

#include <fmt/format.h>

namespace nelf {
namespace {

using N = KeyPress::Named;
KeyPress named(N n) { return KeyPress::of(n); }
KeyPress ch(char32_t c) { return KeyPress::of(c); }

}  // namespace

const std::vector<KeyBinding>& key_bindings() {
  using C = Command;
  using S = KeyScope;
  static const std::vector<KeyBinding> table = {
      {S::play, {{named(N::space), C::pause}}, "space", "space", "pause / play", "", ""},
      {S::play,
       {{named(N::left), C::seek_back_10s}, {named(N::right), C::seek_forward_10s}},
       "left right",
       "← / →",
       "seek 10 s back / forward",
       "",
       ""},
      {S::play,
       {{named(N::down), C::seek_back_60s}, {named(N::up), C::seek_forward_60s}},
       "down up",
       "↓ / ↑",
       "seek 60 s back / forward",
       "",
       ""},
      {S::play,
       {{ch(U'+'), C::screen_farther},
        {ch(U'='), C::screen_farther},
        {ch(U'-'), C::screen_nearer},
        {ch(U'_'), C::screen_nearer}},
       "+ -",
       "+ / −",
       "screen distance x1.25 / /1.25",
       "(the plane the content is rendered at)",
       ""},
      {S::play, {{ch(U'['), C::ipd_narrower}, {ch(U']'), C::ipd_wider}}, "[ ]", "[ / ]", "IPD -/+ 0.5 mm", "", ""},
      {S::play, {{ch(U's'), C::swap_eyes}, {ch(U'S'), C::swap_eyes}}, "s", "s", "swap the eyes", "", ""},
      {S::play,
       {{ch(U'c'), C::calibration_grid}, {ch(U'C'), C::calibration_grid}},
       "c",
       "c",
       "calibration grid on / off",
       "(`nelf calibrate`'s grid, 16 cells, yellow centre cross, L/R, over both views: alignment of the eyes "
       "and the lens grid)",
       ""},
      {S::play,
       {{ch(U'>'), C::next_file}, {named(N::enter), C::next_file}, {ch(U'<'), C::previous_file}},
       "> Enter <",
       "`>`, Enter / `<`",
       "next / previous file of the playlist",
       "(on a photo also → / ←)",
       ""},
      {S::play, {{ch(U'f'), C::fullscreen}, {ch(U'F'), C::fullscreen}}, "f", "f", "fullscreen on / off", "", ""},
      {S::play, {{ch(U'o'), C::show_progress}}, "o", "o", "time and seek bar for 2 s", "(also after every seek)", ""},
      {S::play, {{ch(U'O'), C::keep_progress}}, "O", "O", "time and seek bar always on / off", "", ""},
      {S::play,
       {{ch(U'9'), C::volume_down}, {ch(U'/'), C::volume_down}, {ch(U'0'), C::volume_up}, {ch(U'*'), C::volume_up}},
       "9 0",
       "9 / 0, `/` / `*`",
       "volume -/+ 2",
       "(0 to 130; the change is heard after the half second of sound already queued)",
       ""},
      {S::play, {{ch(U'm'), C::mute}, {ch(U'M'), C::mute}}, "m", "m", "mute on / off", "", ""},
      {S::play,
       {{ch(U'#'), C::next_audio_track}},
       "#",
       "#",
       "next audio track",
       "(after the last, the first; the sound restarts where the picture is)",
       ""},
      {S::play,
       {{ch(U'h'), C::help}, {ch(U'H'), C::help}, {ch(U'?'), C::help}},
       "h",
       "h",
       "this help",
       "(one line per press; all of it in the terminal)",
       ""},
      {S::play,
       {{named(N::escape), C::quit}, {ch(U'q'), C::quit}, {ch(U'Q'), C::quit}},
       "q Esc",
       "q, Esc",
       "quit",
       "",
       ""},

      {S::calibrate, {{named(N::tab), C::next_eye}}, "Tab", "`Tab`", "adjust both eyes / left / right", "", ""},
      {S::calibrate,
       {{named(N::left), C::shift_left},
        {named(N::right), C::shift_right},
        {named(N::up), C::shift_up},
        {named(N::down), C::shift_down}},
       "arrows",
       "arrows",
       "shift 1 px (Shift+arrow 0.1 px)",
       "",
       "`calibration.<eye>.shift_px`"},
      {S::calibrate,
       {{ch(U'r'), C::rotate_less}, {ch(U'R'), C::rotate_more}},
       "r R",
       "`r` / `R`",
       "rotation -/+0.05 deg",
       "(added to the lens array's)",
       "`calibration.<eye>.rotation_deg`"},
      {S::calibrate,
       {{ch(U'p'), C::pitch_less}, {ch(U'P'), C::pitch_more}},
       "p P",
       "`p` / `P`",
       "pitch scale -/+0.0005",
       "",
       "`calibration.<eye>.pitch_scale`"},
      {S::calibrate,
       {{ch(U'g'), C::gap_less}, {ch(U'G'), C::gap_more}},
       "g G",
       "`g` / `G`",
       "lens gap -/+0.005 mm",
       "(starts from Eq. 1 when the profile leaves it out)",
       "`lens_array.gap_mm`"},
      {S::calibrate,
       {{ch(U'['), C::ipd_narrower}, {ch(U']'), C::ipd_wider}},
       "[ ]",
       "`[` / `]`",
       "IPD -/+0.5 mm",
       "",
       "`viewing.ipd_mm`"},
      {S::calibrate,
       {{ch(U'd'), C::prescription_less}, {ch(U'D'), C::prescription_more}},
       "d D",
       "`d` / `D`",
       "prescription -/+0.25 D",
       "(a myope's far point pulls the screen in)",
       "`correction.prescription_diopters`"},
      {S::calibrate,
       {{ch(U'1'), C::pattern_stripes},
        {ch(U'2'), C::pattern_grid},
        {ch(U'3'), C::pattern_snellen},
        {ch(U'4'), C::pattern_white}},
       "1 2 3 4",
       "`1` `2` `3` `4`",
       "stripes, grid, Snellen chart, white",
       "",
       ""},
      {S::calibrate, {{ch(U'w'), C::save}}, "w", "`w`", "save to --save now", "", ""},
      {S::calibrate,
       {{ch(U'h'), C::help}, {ch(U'?'), C::help}},
       "h",
       "`h`",
       "this help",
       "(one line per press; all of it in the terminal)",
       ""},
      {S::calibrate,
       {{named(N::escape), C::quit}, {ch(U'q'), C::quit}},
       "q Esc",
       "`q`, `Esc`",
       "quit (saves to --save)",
       "(also on closing the window or Ctrl-C; says where)",
       ""},

      {S::defects, {{named(N::tab), C::next_eye}}, "Tab", "`Tab`", "the other eye", "(each eye keeps its cursor)", ""},
      {S::defects,
       {{named(N::left), C::cursor_left},
        {named(N::right), C::cursor_right},
        {named(N::up), C::cursor_up},
        {named(N::down), C::cursor_down}},
       "arrows",
       "arrows",
       "cursor 1 px (Shift 10 px, Ctrl 100 px)",
       "(a crosshair with a gap: the pixel under it and its neighbours stay visible)",
       ""},
      {S::defects,
       {{named(N::space), C::field_next},
        {ch(U'1'), C::field_black},
        {ch(U'2'), C::field_white},
        {ch(U'3'), C::field_red},
        {ch(U'4'), C::field_green},
        {ch(U'5'), C::field_blue}},
       "space 1-5",
       "`space`, `1`-`5`",
       "field colour: next / black, white, red, green, blue",
       "(Shift+space back; stuck pixels stand out on black, dead ones on white)",
       ""},
      {S::defects,
       {{ch(U'd'), C::mark_dead}, {ch(U'D'), C::mark_dead}},
       "d",
       "`d`",
       "mark the pixel dead",
       "(it shows black whatever it is sent)",
       ""},
      {S::defects,
       {{ch(U's'), C::mark_stuck}, {ch(U'S'), C::mark_stuck}},
       "s",
       "`s`",
       "mark the pixel stuck at the field's colour",
       "(cycle the field until the pixel disappears into it, then `s`: one that vanishes on white is stuck "
       "white)",
       ""},
      {S::defects,
       {{ch(U'u'), C::unmark}, {ch(U'U'), C::unmark}, {named(N::backspace), C::unmark}},
       "u Backspace",
       "`u`, `Backspace`",
       "unmark the pixel",
       "",
       ""},
      {S::defects,
       {{ch(U'n'), C::next_defect}, {ch(U'N'), C::next_defect}},
       "n",
       "`n`",
       "cursor to the next marked pixel",
       "(in the map's order, either eye)",
       ""},
      {S::defects,
       {{ch(U't'), C::status_line}, {ch(U'T'), C::status_line}},
       "t",
       "`t`",
       "status line on / off",
       "(eye, x, y, field, defects; it moves away from the cursor)",
       ""},
      {S::defects, {{ch(U'w'), C::save}, {ch(U'W'), C::save}}, "w", "`w`", "save the defect map now", "", ""},
      {S::defects,
       {{ch(U'h'), C::help}, {ch(U'H'), C::help}, {ch(U'?'), C::help}},
       "h",
       "`h`",
       "this help",
       "(one line per press; all of it in the terminal)",
       ""},
      {S::defects,
       {{named(N::escape), C::quit}, {ch(U'q'), C::quit}, {ch(U'Q'), C::quit}},
       "q Esc",
       "`q`, `Esc`",
       "quit (saves the defect map)",
       "(also on closing the window or Ctrl-C; says where)",
       ""},
  };
  return table;
}

std::optional<Command> command_for(KeyScope scope, const KeyPress& key) {
  for (const KeyBinding& row : key_bindings()) {
    if (row.scope != scope) continue;
    for (const auto& [press, command] : row.keys) {
      if (press.named != N::none ? key.is(press.named) : (!key.ctrl && !key.alt && key.is(press.character)))
        return command;
    }
  }
  return std::nullopt;
}

std::vector<std::string> key_help(KeyScope scope) {
  std::vector<std::string> lines;
  for (const KeyBinding& row : key_bindings())
    if (row.scope == scope) lines.push_back(fmt::format("{}: {}", row.label, row.help));
  return lines;
}

std::string key_table_markdown(KeyScope scope) {
  const bool with_profile_key = scope == KeyScope::calibrate;
  std::string table =
      with_profile_key ? "| key | changes | profile key |\n|---|---|---|\n" : "| key | does |\n|---|---|\n";
  for (const KeyBinding& row : key_bindings()) {
    if (row.scope != scope) continue;
    std::string does(row.help);
    if (!row.detail.empty()) does += fmt::format(" {}", row.detail);
    table += with_profile_key ? fmt::format("| {} | {} | {} |\n", row.markdown_label, does, row.profile_key)
                              : fmt::format("| {} | {} |\n", row.markdown_label, does);
  }
  return table;
}

}  // namespace nelf
