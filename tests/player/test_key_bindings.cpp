// The one table of keys (player/key_bindings): what play and calibrate do with a key, their help
// and the README's key tables all come from it.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

#include "player/calibration_controls.hpp"
#include "player/defect_marking.hpp"
#include "player/key_bindings.hpp"

namespace nelf {
namespace {

TEST(KeyBindings, NoKeyMeansTwoThingsInOneScope) {
  for (const KeyScope scope : {KeyScope::play, KeyScope::calibrate, KeyScope::defects}) {
    std::set<std::tuple<int, char32_t, bool>> seen;
    for (const KeyBinding& row : key_bindings()) {
      if (row.scope != scope) continue;
      EXPECT_FALSE(row.keys.empty()) << row.label;
      for (const auto& [press, command] : row.keys)
        EXPECT_TRUE(seen.insert({static_cast<int>(press.named), press.character, press.ctrl}).second) << row.label;
    }
  }
}

TEST(KeyBindings, KeysMeanWhatTheHelpSays) {
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(KeyPress::Named::space)), Command::pause);
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(U'Q')), Command::quit);
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(U'h')), Command::help);
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(U'=')), Command::screen_farther);
  EXPECT_EQ(command_for(KeyScope::calibrate, KeyPress::of(KeyPress::Named::left)), Command::shift_left);
  EXPECT_EQ(command_for(KeyScope::calibrate, KeyPress::of(U'R')), Command::rotate_more);
  EXPECT_EQ(command_for(KeyScope::calibrate, KeyPress::of(U's')), std::nullopt);           // play's, not calibrate's
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(U'r')), Command::subtitles_farther);  // calibrate's R rotates
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(U'k')), std::nullopt);
  KeyPress ctrl_s = KeyPress::of(U's');
  ctrl_s.ctrl = true;
  EXPECT_EQ(command_for(KeyScope::play, ctrl_s), Command::screenshot);
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(U's')), Command::swap_eyes);
  // --defects: d and s mark (calibrate's d is the prescription), arrows move the cursor.
  EXPECT_EQ(command_for(KeyScope::defects, KeyPress::of(U'd')), Command::mark_dead);
  EXPECT_EQ(command_for(KeyScope::calibrate, KeyPress::of(U'd')), Command::prescription_less);
  EXPECT_EQ(command_for(KeyScope::defects, KeyPress::of(U's')), Command::mark_stuck);
  EXPECT_EQ(command_for(KeyScope::defects, KeyPress::of(KeyPress::Named::backspace)), Command::unmark);
  EXPECT_EQ(command_for(KeyScope::defects, KeyPress::of(KeyPress::Named::up)), Command::cursor_up);
  EXPECT_EQ(command_for(KeyScope::defects, KeyPress::of(U'r')), std::nullopt);
  // Shift+arrow is still the arrow (calibrate's fine shift); Ctrl+q is not q.
  KeyPress shifted = KeyPress::of(KeyPress::Named::left);
  shifted.shift = true;
  EXPECT_EQ(command_for(KeyScope::calibrate, shifted), Command::shift_left);
  KeyPress ctrl_q = KeyPress::of(U'q');
  ctrl_q.ctrl = true;
  EXPECT_EQ(command_for(KeyScope::play, ctrl_q), std::nullopt);
}

TEST(KeyBindings, HelpIsOneLinePerRow) {
  const auto play = key_help(KeyScope::play);
  EXPECT_EQ(play.front(), "space: pause / play");
  EXPECT_EQ(play.back(), "q Esc: quit");
  EXPECT_EQ(CalibrationControls::help_lines(), key_help(KeyScope::calibrate));
  EXPECT_EQ(CalibrationControls::help_lines().front(), "Tab: adjust both eyes / left / right");
  EXPECT_EQ(DefectMarking::help_lines(), key_help(KeyScope::defects));
  EXPECT_EQ(DefectMarking::help_lines().back(), "q Esc: quit (saves the defect map)");
}

// The configuration file's [keys]: a rebound key means its new command in play only, the key it
// took loses its old one, and h says so: the key's own line, the old row without it.
TEST(KeyBindings, RebindingsChangeWhatPlaysKeysDoAndTheHelp) {
  const KeyRebindings keys = {{KeyPress::of(U'x'), Command::swap_eyes},
                              {KeyPress::of(U's'), std::nullopt},
                              {KeyPress::of(KeyPress::Named::left), Command::quit}};
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(U'x'), keys), Command::swap_eyes);
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(U'x')), std::nullopt);
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(U's'), keys), std::nullopt);  // "ignore"
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(U'S'), keys), Command::swap_eyes);
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(KeyPress::Named::left), keys), Command::quit);
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(KeyPress::Named::right), keys), Command::seek_forward_10s);
  // Not calibrate's keys.
  EXPECT_EQ(command_for(KeyScope::calibrate, KeyPress::of(KeyPress::Named::left), keys), Command::shift_left);

  const auto help = key_help(KeyScope::play, keys);
  const auto has = [&](const std::string& line) { return std::find(help.begin(), help.end(), line) != help.end(); };
  EXPECT_TRUE(has("x: swap the eyes"));
  EXPECT_TRUE(has("S: swap the eyes"));  // s is ignored now, S still swaps
  EXPECT_FALSE(has("s: swap the eyes"));
  EXPECT_TRUE(has("right: seek 10 s back / forward"));
  EXPECT_TRUE(has("left: quit"));
  EXPECT_TRUE(has("q Esc: quit"));
  EXPECT_EQ(key_help(KeyScope::calibrate, keys), key_help(KeyScope::calibrate));
  // A command of a row with two gets its name.
  EXPECT_EQ(key_help(KeyScope::play, {{KeyPress::of(U'z'), Command::seek_back_60s}}).back(), "z: seek back 60s");
}

TEST(KeyBindings, KeyNamesAreMpvsAndOneCharacter) {
  EXPECT_EQ(parse_key_name("SPACE")->named, KeyPress::Named::space);
  EXPECT_EQ(parse_key_name("left")->named, KeyPress::Named::left);
  EXPECT_EQ(parse_key_name("PGDWN")->named, KeyPress::Named::page_down);
  EXPECT_EQ(parse_key_name("Esc")->named, KeyPress::Named::escape);
  EXPECT_EQ(parse_key_name("BS")->named, KeyPress::Named::backspace);
  EXPECT_EQ(parse_key_name("x")->character, U'x');
  EXPECT_EQ(parse_key_name("+")->character, U'+');
  EXPECT_EQ(parse_key_name("\xc3\xa9")->character, U'\u00e9');      // é
  const std::optional<KeyPress> ctrl_s = parse_key_name("ctrl+s");  // as key_name() writes it, any case
  ASSERT_TRUE(ctrl_s);
  EXPECT_TRUE(ctrl_s->ctrl);
  EXPECT_EQ(ctrl_s->character, U's');
  EXPECT_EQ(key_name(*ctrl_s), "Ctrl+s");
  for (const char* bad : {"", "xy", "Ctrl+", "Ctrl+xy", "Ctrl+ ", " ", "\x01", "\xc3"})
    EXPECT_EQ(parse_key_name(bad), std::nullopt) << bad;
  EXPECT_EQ(key_name(*parse_key_name("\xc3\xa9")), "\xc3\xa9");
  EXPECT_EQ(key_name(KeyPress::of(KeyPress::Named::escape)), "Esc");
}

TEST(KeyBindings, EveryPlayCommandHasAName) {
  for (const KeyBinding& row : key_bindings()) {
    if (row.scope != KeyScope::play) continue;
    for (const auto& [press, command] : row.keys) {
      const std::string_view name = command_name(command);
      EXPECT_FALSE(name.empty()) << row.label;
      EXPECT_EQ(command_named(name), command) << name;
    }
  }
  EXPECT_EQ(command_named("swap-eyes"), Command::swap_eyes);
  EXPECT_EQ(command_named("swap_eyes"), std::nullopt);
  EXPECT_EQ(command_name(Command::rotate_less), "");  // calibrate's
}

TEST(KeyBindings, ReadmeTablesAreTheTable) {
  std::ifstream in(NELF_SOURCE_DIR "/README.md");
  ASSERT_TRUE(in) << "README.md not found";
  std::stringstream readme;
  readme << in.rdbuf();
  for (const KeyScope scope : {KeyScope::play, KeyScope::calibrate, KeyScope::defects}) {
    const std::string table = key_table_markdown(scope);
    EXPECT_NE(readme.str().find(table), std::string::npos)
        << "README.md lacks (or has another version of) this table:\n"
        << table;
  }
}

}  // namespace
}  // namespace nelf
