// The keys of `nelf calibrate --defects` (player/defect_marking): the cursor stays on the panel,
// marks follow the stuck colour rule, the panels show the field, the cursor and the markers without
// hiding the pixels, and the map is saved where the profile names it (or beside --save) and reads
// back equal.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>

#include "core/user_error.hpp"
#include "optics/defect_map.hpp"
#include "player/defect_marking.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {
// This file's own names: its suite is compiled as one unit (tests/CMakeLists.txt).
namespace test_defect_marking {

using Named = KeyPress::Named;
using test::TempDir;

constexpr std::array<int, 2> kPanel = {1280, 720};

KeyPress key(char32_t c) { return KeyPress::of(c); }
KeyPress key(Named n, bool shift = false, bool ctrl = false) {
  KeyPress k = KeyPress::of(n);
  k.shift = shift;
  k.ctrl = ctrl;
  return k;
}

DefectStep press(DefectMarking& m, const std::vector<KeyPress>& keys) {
  DefectStep last;
  for (const auto& k : keys) last = m.apply(k);
  return last;
}

PixelDefect dead(Eye eye, int x, int y) { return PixelDefect{eye, x, y, DefectKind::dead, {0, 0, 0}}; }
PixelDefect stuck(Eye eye, int x, int y, std::array<std::uint8_t, 3> rgb) {
  return PixelDefect{eye, x, y, DefectKind::stuck, rgb};
}

bool is(const Rgba& p, std::array<std::uint8_t, 3> rgb) {
  return p.r == rgb[0] / 255.f && p.g == rgb[1] / 255.f && p.b == rgb[2] / 255.f;
}

TEST(DefectMarking, CursorStartsCentredMovesBySteps_AndStaysOnThePanel) {
  DefectMarking m(kPanel, {});
  EXPECT_EQ(m.eye(), Eye::left);
  EXPECT_EQ(m.cursor(), (std::array<int, 2>{640, 360}));
  press(m, {key(Named::left), key(Named::up), key(Named::up)});
  EXPECT_EQ(m.cursor(), (std::array<int, 2>{639, 358}));
  press(m, {key(Named::right, true), key(Named::down, false, true)});  // Shift: 10, Ctrl: 100
  EXPECT_EQ(m.cursor(), (std::array<int, 2>{649, 458}));
  for (int i = 0; i < 10; ++i) m.apply(key(Named::left, false, true));
  EXPECT_EQ(m.cursor(), (std::array<int, 2>{0, 458}));
  auto step = m.apply(key(Named::left));
  EXPECT_FALSE(step.changed);
  EXPECT_EQ(step.message, "edge of the panel");
  for (int i = 0; i < 20; ++i) m.apply(key(Named::right, false, true));
  for (int i = 0; i < 10; ++i) m.apply(key(Named::down, true, true));  // Ctrl wins over Shift
  EXPECT_EQ(m.cursor(), (std::array<int, 2>{1279, 719}));
  // Each eye has its own cursor.
  step = m.apply(key(Named::tab));
  EXPECT_TRUE(step.changed);
  EXPECT_EQ(m.eye(), Eye::right);
  EXPECT_EQ(m.cursor(), (std::array<int, 2>{640, 360}));
  for (int i = 0; i < 10; ++i) m.apply(key(Named::up, false, true));
  EXPECT_EQ(m.cursor(), (std::array<int, 2>{640, 0}));
  m.apply(key(Named::tab));
  EXPECT_EQ(m.cursor(), (std::array<int, 2>{1279, 719}));
  EXPECT_EQ(m.cursor(Eye::right), (std::array<int, 2>{640, 0}));
}

TEST(DefectMarking, SpaceCyclesTheFieldsAndDigitsChooseThem) {
  DefectMarking m(kPanel, {});
  EXPECT_EQ(m.field(), DefectField::black);
  std::vector<std::string> seen;
  for (int i = 0; i < 5; ++i) {
    m.apply(key(Named::space));
    seen.push_back(defect_field_name(m.field()));
  }
  EXPECT_EQ(seen, (std::vector<std::string>{"white", "red", "green", "blue", "black"}));
  m.apply(key(Named::space, true));  // Shift+space: back
  EXPECT_EQ(m.field(), DefectField::blue);
  m.apply(key(U'3'));
  EXPECT_EQ(m.field(), DefectField::red);
  EXPECT_FALSE(m.apply(key(U'3')).changed);
  m.apply(key(U'2'));
  EXPECT_EQ(m.field(), DefectField::white);
  EXPECT_EQ(defect_field_names(), (std::vector<std::string>{"black", "white", "red", "green", "blue"}));
  EXPECT_EQ(parse_defect_field("green"), DefectField::green);
  EXPECT_EQ(parse_defect_field("Green"), std::nullopt);
}

TEST(DefectMarking, MarksDeadAndStuckAtTheFieldItDisappearsInto) {
  DefectMarking m(kPanel, {});
  auto step = m.apply(key(U'd'));
  EXPECT_TRUE(step.marked);
  EXPECT_EQ(step.message, "marked left 640 360 dead (1 defect)");
  EXPECT_EQ(m.status_line(), "left 640 360 | field black | 1 defect | marked dead");
  // On black a stuck pixel's colour is unknown (and one stuck at black is dead): refused.
  m.apply(key(Named::right));
  step = m.apply(key(U's'));
  EXPECT_FALSE(step.marked);
  EXPECT_NE(step.message.find("not marked: a pixel stuck at black is dead (d)"), std::string::npos) << step.message;
  // It vanishes on the white field: stuck white.
  m.apply(key(U'2'));
  step = m.apply(key(U's'));
  EXPECT_EQ(step.message, "marked left 641 360 stuck 255 255 255 (2 defects)");
  // Cycled on, it vanishes on the green field instead: the mark changes, the pixel keeps its place.
  press(m, {key(Named::space), key(Named::space)});
  EXPECT_EQ(m.field(), DefectField::green);
  step = m.apply(key(U'S'));
  EXPECT_EQ(step.message, "marked left 641 360 stuck 0 255 0 (2 defects)");
  EXPECT_EQ(m.apply(key(U's')).message, "already marked: left 641 360 stuck 0 255 0");
  // The other eye, blue; then the first mark made dead again is unchanged.
  press(m, {key(Named::tab), key(Named::down), key(U'5'), key(U's')});
  press(m, {key(Named::tab), key(Named::left), key(U'd')});
  EXPECT_EQ(m.map().defects,
            (std::vector<PixelDefect>{dead(Eye::left, 640, 360), stuck(Eye::left, 641, 360, {0, 255, 0}),
                                      stuck(Eye::right, 640, 361, {0, 0, 255})}));
  // Unmark: u and Backspace; a pixel not marked says so.
  step = m.apply(key(U'u'));
  EXPECT_EQ(step.message, "unmarked left 640 360 dead (2 defects)");
  step = m.apply(key(Named::backspace));
  EXPECT_FALSE(step.marked);
  EXPECT_EQ(step.message, "left 640 360 is not marked");
  m.apply(key(Named::right));
  EXPECT_TRUE(m.apply(key(Named::backspace)).marked);
  EXPECT_EQ(m.map().defects, (std::vector<PixelDefect>{stuck(Eye::right, 640, 361, {0, 0, 255})}));
}

TEST(DefectMarking, NextGoesThroughTheMarksOfBothEyes) {
  DefectMap map;
  map.defects = {dead(Eye::right, 10, 20), stuck(Eye::left, 5, 6, {255, 255, 255})};
  DefectMarking m(kPanel, map);
  EXPECT_EQ(m.apply(key(U'n')).message, "defect 1 of 2: right 10 20 dead");
  EXPECT_EQ(m.eye(), Eye::right);
  EXPECT_EQ(m.cursor(), (std::array<int, 2>{10, 20}));
  EXPECT_EQ(m.apply(key(U'n')).message, "defect 2 of 2: left 5 6 stuck 255 255 255");
  EXPECT_EQ(m.cursor(), (std::array<int, 2>{5, 6}));
  m.apply(key(U'n'));
  EXPECT_EQ(m.eye(), Eye::right);
  EXPECT_EQ(DefectMarking(kPanel, {}).apply(key(U'n')).message, "no pixel is marked");
}

TEST(DefectMarking, OtherKeysAndQuit) {
  DefectMarking m(kPanel, {});
  EXPECT_TRUE(m.apply(key(U'q')).quit);
  EXPECT_TRUE(m.apply(key(Named::escape)).quit);
  EXPECT_TRUE(m.apply(key(U'w')).save);
  EXPECT_TRUE(m.apply(key(U'h')).help);
  EXPECT_EQ(m.apply(key(U'r')).message, "key 'r' does nothing (h: help)");  // calibrate's, not this mode's
  KeyPress ctrl_c = key(U'c');
  ctrl_c.ctrl = true;
  EXPECT_TRUE(m.apply(ctrl_c).quit);
  EXPECT_TRUE(m.status_shown());
  m.apply(key(U't'));
  EXPECT_FALSE(m.status_shown());
}

TEST(DefectMarking, PanelsShowTheFieldTheCursorAndMarkersWithoutHidingPixels) {
  DefectMap map;
  map.defects = {dead(Eye::left, 100, 100), stuck(Eye::right, 200, 50, {255, 255, 255}), dead(Eye::left, 0, 0)};
  DefectMarking m(kPanel, map, DefectField::red);
  const auto red = defect_field_rgb(DefectField::red);
  const auto cyan = DefectMarking::contrast_rgb(DefectField::red);
  EXPECT_EQ(cyan, (std::array<std::uint8_t, 3>{0, 255, 255}));
  EXPECT_EQ(DefectMarking::contrast_rgb(DefectField::black), (std::array<std::uint8_t, 3>{255, 255, 255}));
  const Image left = m.panel_image(Eye::left, "");
  const Image right = m.panel_image(Eye::right, "");
  ASSERT_EQ(left.width(), 1280);
  ASSERT_EQ(left.height(), 720);
  // The cursor at (640, 360): its pixel and everything within the gap are the field; the arms
  // (4 to 13 px out along the row and the column) are cyan.
  const int g = DefectMarking::cursor_gap_px, a = DefectMarking::cursor_arm_px;
  for (int dy = -(g - 1); dy <= g - 1; ++dy)
    for (int dx = -(g - 1); dx <= g - 1; ++dx) EXPECT_TRUE(is(left.at(640 + dx, 360 + dy), red)) << dx << "," << dy;
  for (int i = g; i < g + a; ++i) {
    EXPECT_TRUE(is(left.at(640 + i, 360), cyan)) << i;
    EXPECT_TRUE(is(left.at(640 - i, 360), cyan)) << i;
    EXPECT_TRUE(is(left.at(640, 360 + i), cyan)) << i;
    EXPECT_TRUE(is(left.at(640, 360 - i), cyan)) << i;
  }
  EXPECT_TRUE(is(left.at(640 + g + a, 360), red));
  EXPECT_TRUE(is(left.at(640 + g, 361), red));
  // Only the selected eye has the cursor.
  EXPECT_TRUE(is(right.at(640 + g, 360), red));
  // A dead pixel's marker: the ring 2 px out, whole; the pixel and its neighbours untouched.
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) EXPECT_TRUE(is(left.at(100 + dx, 100 + dy), red));
  for (int i = -2; i <= 2; ++i) {
    EXPECT_TRUE(is(left.at(100 + i, 98), cyan)) << i;
    EXPECT_TRUE(is(left.at(102, 100 + i), cyan)) << i;
  }
  EXPECT_TRUE(is(left.at(100, 97), red));
  // A stuck pixel's ring is dotted (the corners drawn), on its own eye only.
  EXPECT_TRUE(is(right.at(202, 52), cyan));
  EXPECT_TRUE(is(right.at(202, 51), red));
  EXPECT_TRUE(is(right.at(202, 50), cyan));
  EXPECT_TRUE(is(right.at(200, 50), red));
  EXPECT_TRUE(is(left.at(202, 52), red));
  // A marker at the corner is clipped to the panel.
  EXPECT_TRUE(is(left.at(2, 0), cyan));
  EXPECT_TRUE(is(left.at(0, 0), red));
  // field_image: the same without the cursor.
  const Image plain = DefectMarking::field_image(kPanel, DefectField::red, map, Eye::left);
  EXPECT_TRUE(is(plain.at(640 + g, 360), red));
  EXPECT_TRUE(is(plain.at(102, 100), cyan));
}

// The rows of `image` that differ from the field anywhere.
std::vector<int> changed_rows(const Image& image, std::array<std::uint8_t, 3> field) {
  std::vector<int> rows;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      if (!is(image.at(x, y), field)) {
        rows.push_back(y);
        break;
      }
  return rows;
}

TEST(DefectMarking, TheStatusLineKeepsAwayFromTheCursor) {
  DefectMarking m(kPanel, {}, DefectField::white);
  const auto white = defect_field_rgb(DefectField::white);
  // The cursor in the top half: the text along the bottom edge (and the cursor's own rows).
  m.apply(key(Named::up, false, true));  // y 260
  auto rows = changed_rows(m.panel_image(Eye::left, m.status_line()), white);
  ASSERT_FALSE(rows.empty());
  EXPECT_EQ(rows.back(), 719);
  EXPECT_GE(rows.front(), 260 - DefectMarking::cursor_gap_px - DefectMarking::cursor_arm_px);
  const auto bottom_band = std::count_if(rows.begin(), rows.end(), [](int y) { return y > 600; });
  EXPECT_GT(bottom_band, 15);  // a line of text about 22 px high
  // In the bottom half: along the top edge.
  for (int i = 0; i < 3; ++i) m.apply(key(Named::down, false, true));
  rows = changed_rows(m.panel_image(Eye::left, m.status_line()), white);
  EXPECT_EQ(rows.front(), 0);
  EXPECT_EQ(rows.back(), 560 + DefectMarking::cursor_gap_px + DefectMarking::cursor_arm_px - 1);
  // Not on the other eye; none when hidden (t).
  EXPECT_TRUE(changed_rows(m.panel_image(Eye::right, m.status_line()), white).empty());
  m.apply(key(U't'));
  rows = changed_rows(m.panel_image(Eye::left, m.status_line()), white);
  EXPECT_EQ(rows.front(), 560 - DefectMarking::cursor_gap_px - DefectMarking::cursor_arm_px + 1);
}

TEST(DefectMarking, SavePathRules) {
  Profile builtin = load_profile("hmz-t1");
  // No map named: <stem>.defects beside --save; without --save nowhere.
  auto where = defect_map_save(builtin, "cal/my-hmz.toml");
  EXPECT_EQ(where.map, std::filesystem::path("cal/my-hmz.defects"));
  EXPECT_EQ(where.profile, "cal/my-hmz.toml");
  where = defect_map_save(builtin, "");
  EXPECT_TRUE(where.map.empty());
  EXPECT_TRUE(where.profile.empty());
  // A map named: that file, whether or not a profile is saved too.
  Profile named = builtin;
  named.correction.defect_map = "panel.defects";
  named.correction.defect_map_path = "/somewhere/panel.defects";
  EXPECT_EQ(defect_map_save(named, "").map, std::filesystem::path("/somewhere/panel.defects"));
  where = defect_map_save(named, "other/mine.toml");
  EXPECT_EQ(where.map, std::filesystem::path("/somewhere/panel.defects"));
  EXPECT_EQ(where.profile, "other/mine.toml");
}

TEST(DefectMarking, SavedMapAndProfileReadBack) {
  TempDir dir;
  // From a built-in: the map beside the saved profile, which names it.
  DefectMarking m(load_profile("hmz-t1").display.resolution, {});
  press(m, {key(U'd'), key(Named::right, true), key(U'2'), key(U's'), key(Named::tab), key(Named::up), key(U'3'),
            key(U's')});
  const auto save = (dir / "mine.toml").string();
  auto where = defect_map_save(load_profile("hmz-t1"), save);
  const std::string line = save_defect_map(load_profile("hmz-t1"), m.map(), where);
  EXPECT_EQ(line, fmt::format("saved 3 defects to {} and {} naming it", (dir / "mine.defects").string(), save));
  const DefectMap expected{{dead(Eye::left, 640, 360), stuck(Eye::left, 650, 360, {255, 255, 255}),
                            stuck(Eye::right, 640, 359, {255, 0, 0})}};
  EXPECT_EQ(read_defect_map(dir / "mine.defects", {1280, 720}), expected);
  EXPECT_EQ(test::read_file(dir / "mine.defects"), defect_map_text(expected));
  Profile saved = load_profile(save);
  EXPECT_EQ(saved.correction.defect_map, "mine.defects");
  ASSERT_TRUE(saved.correction.defects);
  EXPECT_EQ(*saved.correction.defects, expected);

  // Again from the saved profile, without --save: the map it names is rewritten, the profile left.
  const std::string profile_text = test::read_file(save);
  DefectMarking again(saved.display.resolution, *saved.correction.defects);
  again.apply(key(U'u'));  // the left eye's dead pixel at the centre
  where = defect_map_save(saved, "");
  EXPECT_EQ(save_defect_map(saved, again.map(), where),
            fmt::format("saved 2 defects to {}", (dir / "mine.defects").string()));
  EXPECT_EQ(read_defect_map(dir / "mine.defects", {1280, 720}).defects.size(), 2u);
  EXPECT_EQ(test::read_file(save), profile_text);

  // Saved elsewhere: the map stays where the profile named it, the new profile names it from its
  // own directory.
  std::filesystem::create_directory(dir / "other");
  const auto elsewhere = (dir / "other" / "copy.toml").string();
  save_defect_map(saved, again.map(), defect_map_save(saved, elsewhere));
  const Profile copy = load_profile(elsewhere);
  EXPECT_EQ(copy.correction.defect_map, "../mine.defects");
  EXPECT_EQ(*copy.correction.defects, again.map());

  // A map that cannot be written: one line, status 1, naming the file.
  DefectMapSave nowhere{dir / "missing" / "x.defects", ""};
  try {
    save_defect_map(saved, again.map(), nowhere);
    ADD_FAILURE() << "no error";
  } catch (const UserError& e) {
    EXPECT_EQ(e.status(), 1);
    EXPECT_NE(std::string(e.what()).find("x.defects: cannot write the defect map"), std::string::npos) << e.what();
  }
}

}  // namespace test_defect_marking
}  // namespace
}  // namespace nelf
