#include "player/key_bindings.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <initializer_list>

namespace nelf {
namespace {

using N = KeyPress::Named;
KeyPress named(N n) { return KeyPress::of(n); }
KeyPress ch(char32_t c) { return KeyPress::of(c); }
KeyPress ctrl(char32_t c) {
  KeyPress k = KeyPress::of(c);
  k.ctrl = true;
  return k;
}

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
       {{ch(U'v'), C::toggle_subtitles}},
       "v",
       "v",
       "subtitles on / off",
       "(`--no-subs` starts with none)",
       ""},
      {S::play,
       {{ch(U'j'), C::next_subtitle_track}, {ch(U'J'), C::previous_subtitle_track}},
       "j J",
       "j / J",
       "next / previous subtitle track",
       "(the files beside the movie, then its own; off after the last)",
       ""},
      {S::play,
       {{ctrl(U's'), C::screenshot}},
       "Ctrl+s",
       "Ctrl+s",
       "screenshot of the packed frame as the display shows it",
       "(`nelf-shot0001.png`, … in the current folder; mpv's Ctrl+s)",
       ""},
      {S::play,
       {{ctrl(U'v'), C::screenshot_views}},
       "Ctrl+v",
       "Ctrl+v",
       "screenshot of the views side by side at the source's resolution, with the subtitles",
       "(`nelf-views0001.png`, …; a side-by-side stereo picture)",
       ""},
      {S::play,
       {{ch(U'R'), C::subtitles_nearer}, {ch(U'r'), C::subtitles_farther}},
       "R r",
       "R / r",
       "subtitles nearer / farther by 0.25 % of the view width",
       "(`--sub-parallax`; remembered per file)",
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

namespace {

bool matches(const KeyPress& press, const KeyPress& key) {
  return press.named != N::none ? key.is(press.named) : (key.ctrl == press.ctrl && !key.alt && key.is(press.character));
}

const KeyRebinding* rebinding_of(const KeyPress& press, const KeyRebindings& rebindings) {
  for (const KeyRebinding& r : rebindings)
    if (r.key.named == press.named && r.key.character == press.character) return &r;
  return nullptr;
}

struct NamedCommand {
  Command command;
  std::string_view name;
};
// Play's commands by the names a configuration file gives them (kebab case, as mpv's are).
constexpr NamedCommand play_commands[] = {
    {Command::pause, "pause"},
    {Command::seek_back_10s, "seek-back-10s"},
    {Command::seek_forward_10s, "seek-forward-10s"},
    {Command::seek_back_60s, "seek-back-60s"},
    {Command::seek_forward_60s, "seek-forward-60s"},
    {Command::screen_farther, "screen-farther"},
    {Command::screen_nearer, "screen-nearer"},
    {Command::ipd_narrower, "ipd-narrower"},
    {Command::ipd_wider, "ipd-wider"},
    {Command::swap_eyes, "swap-eyes"},
    {Command::calibration_grid, "calibration-grid"},
    {Command::fullscreen, "fullscreen"},
    {Command::next_file, "playlist-next"},
    {Command::previous_file, "playlist-prev"},
    {Command::show_progress, "show-progress"},
    {Command::keep_progress, "keep-progress"},
    {Command::volume_down, "volume-down"},
    {Command::volume_up, "volume-up"},
    {Command::mute, "mute"},
    {Command::next_audio_track, "cycle-audio"},
    {Command::toggle_subtitles, "toggle-subtitles"},
    {Command::next_subtitle_track, "cycle-subtitles"},
    {Command::previous_subtitle_track, "cycle-subtitles-back"},
    {Command::subtitles_nearer, "subtitles-nearer"},
    {Command::subtitles_farther, "subtitles-farther"},
    {Command::screenshot, "screenshot"},
    {Command::screenshot_views, "screenshot-views"},
    {Command::help, "help"},
    {Command::quit, "quit"},
};

struct NamedKey {
  N key;
  std::string_view shown;                         // in the help
  std::initializer_list<std::string_view> names;  // as a configuration file may write it (any case)
};
const NamedKey named_keys[] = {
    {N::space, "space", {"space"}},
    {N::left, "left", {"left"}},
    {N::right, "right", {"right"}},
    {N::up, "up", {"up"}},
    {N::down, "down", {"down"}},
    {N::page_up, "PgUp", {"pgup"}},
    {N::page_down, "PgDn", {"pgdwn", "pgdn"}},
    {N::escape, "Esc", {"esc"}},
    {N::enter, "Enter", {"enter"}},
    {N::tab, "Tab", {"tab"}},
    {N::backspace, "Backspace", {"bs", "backspace"}},
};

bool same_ignoring_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; };
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

// The one code point `text` is in UTF-8; nullopt when it is more, less or not UTF-8.
std::optional<char32_t> single_code_point(std::string_view text) {
  if (text.empty()) return std::nullopt;
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char lead = byte(0);
  std::size_t length = 0;
  char32_t c = 0;
  if (lead < 0x80) {
    length = 1;
    c = lead;
  } else if ((lead & 0xE0) == 0xC0) {
    length = 2;
    c = lead & 0x1F;
  } else if ((lead & 0xF0) == 0xE0) {
    length = 3;
    c = lead & 0x0F;
  } else if ((lead & 0xF8) == 0xF0) {
    length = 4;
    c = lead & 0x07;
  } else {
    return std::nullopt;
  }
  if (text.size() != length) return std::nullopt;
  for (std::size_t i = 1; i < length; ++i) {
    if ((byte(i) & 0xC0) != 0x80) return std::nullopt;
    c = (c << 6) | (byte(i) & 0x3F);
  }
  // Control characters are keys a terminal or window reports by name, or not at all.
  if (c < 0x20 || c == 0x7F) return std::nullopt;
  return c;
}

std::string utf8(char32_t c) {
  std::string out;
  if (c < 0x80) {
    out += static_cast<char>(c);
  } else if (c < 0x800) {
    out += static_cast<char>(0xC0 | (c >> 6));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else if (c < 0x10000) {
    out += static_cast<char>(0xE0 | (c >> 12));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (c >> 18));
    out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  }
  return out;
}

// What a key rebound to `command` does, for its line of the help: its row's help when the row has
// no other command, else the command's name.
std::string rebound_help(Command command) {
  for (const KeyBinding& row : key_bindings()) {
    if (row.scope != KeyScope::play) continue;
    bool has = false, others = false;
    for (const auto& [press, c] : row.keys) (c == command ? has : others) = true;
    if (has && !others) return std::string(row.help);
  }
  std::string name(command_name(command));
  std::replace(name.begin(), name.end(), '-', ' ');
  return name;
}

}  // namespace

std::optional<Command> command_for(KeyScope scope, const KeyPress& key, const KeyRebindings& rebindings) {
  if (scope == KeyScope::play)
    for (const KeyRebinding& r : rebindings)
      if (matches(r.key, key)) return r.command;
  for (const KeyBinding& row : key_bindings()) {
    if (row.scope != scope) continue;
    for (const auto& [press, command] : row.keys)
      if (matches(press, key)) return command;
  }
  return std::nullopt;
}

std::vector<std::string> key_help(KeyScope scope, const KeyRebindings& rebindings) {
  const KeyRebindings& changed = scope == KeyScope::play ? rebindings : KeyRebindings{};
  std::vector<std::string> lines;
  for (const KeyBinding& row : key_bindings()) {
    if (row.scope != scope) continue;
    std::string label;
    bool rebound = false;
    for (const auto& [press, command] : row.keys) {
      if (rebinding_of(press, changed)) {
        rebound = true;
        continue;
      }
      // A row a rebinding changed names each key it still has, a letter once (s for s and S),
      // as the rows' own labels do.
      const bool upper = press.named == N::none && press.character >= U'A' && press.character <= U'Z';
      if (upper && !rebinding_of(KeyPress::of(press.character - U'A' + U'a'), changed) &&
          std::any_of(row.keys.begin(), row.keys.end(),
                      [&](const auto& k) { return k.first.is(press.character - U'A' + U'a'); }))
        continue;
      label += (label.empty() ? "" : " ") + key_name(press);
    }
    if (!rebound)
      lines.push_back(fmt::format("{}: {}", row.label, row.help));
    else if (!label.empty())
      lines.push_back(fmt::format("{}: {}", label, row.help));
  }
  for (const KeyRebinding& r : changed)
    if (r.command) lines.push_back(fmt::format("{}: {}", key_name(r.key), rebound_help(*r.command)));
  return lines;
}

std::string_view command_name(Command command) {
  for (const NamedCommand& c : play_commands)
    if (c.command == command) return c.name;
  return {};
}

std::optional<Command> command_named(std::string_view name) {
  for (const NamedCommand& c : play_commands)
    if (c.name == name) return c.command;
  return std::nullopt;
}

std::vector<std::string> play_command_names() {
  std::vector<std::string> names;
  for (const NamedCommand& c : play_commands) names.emplace_back(c.name);
  return names;
}

std::optional<KeyPress> parse_key_name(std::string_view name) {
  for (const NamedKey& k : named_keys)
    for (const std::string_view n : k.names)
      if (same_ignoring_case(name, n)) return KeyPress::of(k.key);
  if (const std::optional<char32_t> c = single_code_point(name); c && *c != U' ') return KeyPress::of(*c);
  // "Ctrl+s", as key_name() and mpv write a character with Ctrl.
  constexpr std::string_view kCtrl = "Ctrl+";
  if (name.size() > kCtrl.size() && same_ignoring_case(name.substr(0, kCtrl.size()), kCtrl))
    if (const std::optional<char32_t> c = single_code_point(name.substr(kCtrl.size())); c && *c != U' ')
      return ctrl(*c);
  return std::nullopt;
}

std::string key_name(const KeyPress& key) {
  if (key.named == N::none) return (key.ctrl ? "Ctrl+" : "") + utf8(key.character);
  for (const NamedKey& k : named_keys)
    if (k.key == key.named) return std::string(k.shown);
  return "?";
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
