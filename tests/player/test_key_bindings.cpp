// The one table of keys (player/key_bindings): what play and calibrate do with a key, their help
// and the README's key tables all come from it.
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "player/calibration_controls.hpp"
#include "player/defect_marking.hpp"
#include "player/key_bindings.hpp"

namespace nelf {
namespace {

TEST(KeyBindings, NoKeyMeansTwoThingsInOneScope) {
  for (const KeyScope scope : {KeyScope::play, KeyScope::calibrate, KeyScope::defects}) {
    std::set<std::pair<int, char32_t>> seen;
    for (const KeyBinding& row : key_bindings()) {
      if (row.scope != scope) continue;
      EXPECT_FALSE(row.keys.empty()) << row.label;
      for (const auto& [press, command] : row.keys)
        EXPECT_TRUE(seen.insert({static_cast<int>(press.named), press.character}).second) << row.label;
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
  EXPECT_EQ(command_for(KeyScope::calibrate, KeyPress::of(U's')), std::nullopt);  // play's, not calibrate's
  EXPECT_EQ(command_for(KeyScope::play, KeyPress::of(U'r')), std::nullopt);
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
