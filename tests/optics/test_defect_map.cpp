#include <gtest/gtest.h>

#include <string>

#include "optics/defect_map.hpp"
#include "optics/profile.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

constexpr std::array<int, 2> panel{1280, 720};

std::string error_of(const std::string& text) {
  try {
    parse_defect_map(text, "panel.defects", panel);
  } catch (const DefectMapError& e) {
    return e.what();
  }
  return "";
}

TEST(DefectMap, ReadsTheDocumentedForm) {
  const DefectMap map = parse_defect_map(
      "# a comment\n\nleft 640 360 dead\n  right 12 700 stuck 255 255 255   # white\n\tleft 0 0 stuck 0 128 7\r\n", "x",
      panel);
  ASSERT_EQ(map.defects.size(), 3u);
  EXPECT_EQ(map.defects[0].eye, Eye::left);
  EXPECT_EQ(map.defects[0].x, 640);
  EXPECT_EQ(map.defects[0].y, 360);
  EXPECT_EQ(map.defects[0].kind, DefectKind::dead);
  EXPECT_EQ(map.defects[0].shown_rgb(), (std::array<std::uint8_t, 3>{0, 0, 0}));
  EXPECT_EQ(map.defects[1].eye, Eye::right);
  EXPECT_EQ(map.defects[1].kind, DefectKind::stuck);
  EXPECT_EQ(map.defects[1].shown_rgb(), (std::array<std::uint8_t, 3>{255, 255, 255}));
  EXPECT_EQ(map.defects[2].stuck_rgb, (std::array<std::uint8_t, 3>{0, 128, 7}));
  EXPECT_TRUE(parse_defect_map("# nothing\n\n", "x", panel).empty());
}

TEST(DefectMap, OnePixelPerEyeMayBeDefectiveInBoth) {
  EXPECT_EQ(parse_defect_map("left 5 5 dead\nright 5 5 dead\n", "x", panel).defects.size(), 2u);
}

TEST(DefectMap, RefusesEachBadLineNamingFileLineAndRule) {
  EXPECT_EQ(error_of("left 1280 0 dead\n"),
            "panel.defects:1: pixel (1280, 0) is outside the 1280x720 panel (columns 0..1279, rows 0..719)");
  EXPECT_EQ(error_of("\nright 3 -1 dead"),
            "panel.defects:2: pixel (3, -1) is outside the 1280x720 panel (columns 0..1279, rows 0..719)");
  EXPECT_EQ(error_of("left 1 2 dead\n# x\nleft 1 2 stuck 1 1 1\n"),
            "panel.defects:3: left pixel (1, 2) is already given on line 1: one line per pixel");
  EXPECT_NE(error_of("middle 1 2 dead").find("panel.defects:1: the eye must be left or right, got 'middle'"),
            std::string::npos);
  EXPECT_NE(error_of("left 1 2").find("panel.defects:1: a defect is"), std::string::npos);
  EXPECT_NE(error_of("left 1.5 2 dead").find("panel.defects:1: the column and row must be whole numbers"),
            std::string::npos);
  EXPECT_NE(error_of("left 1 2 broken").find("the kind must be dead or stuck, got 'broken'"), std::string::npos);
  EXPECT_NE(error_of("left 1 2 dead 3").find("'dead' takes no values"), std::string::npos);
  EXPECT_NE(error_of("left 1 2 stuck 255 255").find("'stuck' takes three values R G B (0..255), got 2"),
            std::string::npos);
  EXPECT_NE(error_of("left 1 2 stuck 256 0 0").find("a stuck value must be a whole number 0..255, got '256'"),
            std::string::npos);
  EXPECT_NE(error_of("left 99999999999999999999 2 dead").find("whole numbers"), std::string::npos);
  // Every message is one line.
  EXPECT_EQ(error_of("left \x01\x02 2 dead\n").find('\n'), std::string::npos);
}

TEST(DefectMap, WrittenMapReadsBackEqual) {
  test::TempDir dir;
  DefectMap map;
  map.defects.push_back({Eye::left, 640, 360, DefectKind::dead, {}});
  map.defects.push_back({Eye::right, 12, 700, DefectKind::stuck, {255, 255, 255}});
  map.defects.push_back({Eye::left, 0, 719, DefectKind::stuck, {0, 9, 200}});
  write_defect_map(dir / "panel.defects", map);
  EXPECT_EQ(read_defect_map(dir / "panel.defects", panel), map);
  EXPECT_EQ(test::files_in(dir.path()), std::vector<std::string>{"panel.defects"});  // no temporary left
  EXPECT_THROW(write_defect_map(dir / "no-such-dir" / "x.defects", map), DefectMapError);
}

TEST(DefectMap, MissingFileIsOneLine) {
  test::TempDir dir;
  try {
    read_defect_map(dir / "absent.defects", panel);
    FAIL();
  } catch (const DefectMapError& e) {
    EXPECT_NE(std::string(e.what()).find("absent.defects: cannot read the defect map: no such file"),
              std::string::npos);
  }
}

std::string profile_with_map(const std::string& map) {
  return R"(name = "t"
[display]
resolution = [1280, 720]
pixel_pitch_mm = 0.012
[lens_array]
pitch_mm = 1.0
focal_length_mm = 3.3
[viewing]
eye_relief_mm = 25.0
virtual_image_mm = 1000.0
[correction]
defect_map = ")" +
         map + "\"\n";
}

TEST(DefectMap, LoadedWithTheProfileRelativeToIt) {
  test::TempDir dir;
  std::filesystem::create_directories(dir / "device");
  test::write_file(dir / "device" / "panel.defects", "left 640 360 dead\nright 1 2 stuck 255 0 0\n");
  test::write_file(dir / "device" / "p.toml", profile_with_map("panel.defects"));
  const Profile p = load_profile((dir / "device" / "p.toml").string());
  ASSERT_TRUE(p.correction.defects);
  EXPECT_EQ(p.correction.defects->defects.size(), 2u);
  EXPECT_EQ(p.correction.defect_map_path, dir / "device" / "panel.defects");
  // Without a map there is none.
  EXPECT_FALSE(load_profile("hmz-t1").correction.defects);
}

TEST(DefectMap, ProfileRefusesAMissingOrBadMap) {
  test::TempDir dir;
  test::write_file(dir / "p.toml", profile_with_map("absent.defects"));
  try {
    load_profile((dir / "p.toml").string());
    FAIL();
  } catch (const ProfileError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("p.toml:12: correction.defect_map names \"absent.defects\""), std::string::npos) << message;
    EXPECT_NE(message.find("does not exist"), std::string::npos) << message;
  }
  test::write_file(dir / "bad.defects", "left 0 0 dead\nleft 2000 0 dead\n");
  test::write_file(dir / "p.toml", profile_with_map("bad.defects"));
  try {
    load_profile((dir / "p.toml").string());
    FAIL();
  } catch (const DefectMapError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.defects:2: pixel (2000, 0) is outside the 1280x720 panel"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace nelf
