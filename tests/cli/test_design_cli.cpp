// `nelf design`, `nelf profiles`, --version and --help, run as a user would; and every kind of bad
// profile through the CLI: exit status 2, nothing on stdout, one line on stderr naming the file and
// the key.
#include <gtest/gtest.h>

#include <OpenImageIO/imagebuf.h>
#include <algorithm>
#include <nlohmann/json.hpp>

#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::run_nelf;
using test::q;

const char* valid_lens_profile = R"(name = "custom"
[display]
resolution = [1280, 720]
pixel_pitch_mm = 0.012
[lens_array]
pitch_mm = 1.0
focal_length_mm = 3.3
[viewing]
eye_relief_mm = 25.0
virtual_image_mm = 1000.0
)";

std::size_t count_lines(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

// Parses stdout as exactly one JSON value (nlohmann rejects trailing content) that is an object.
nlohmann::json parse_one_object(const std::string& out) {
  nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_TRUE(j.is_object());
  return j;
}

TEST(DesignCli, JsonIsOneObjectWithHmzT1Values) {
  const auto r = run_nelf("design --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  nlohmann::json j;
  ASSERT_NO_THROW(j = parse_one_object(r.out)) << r.out;
  for (const char* key :
       {"profile", "gap_mm", "magnification", "elemental_image_mm", "lenses", "fov_deg", "resolution_px", "eye_box_mm",
        "depth_of_field_mm", "views", "diffraction_pitch_um", "simple_magnifier_min_focal_mm"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["profile"], "hmz-t1");
  EXPECT_EQ(j["lenses"], nlohmann::json::array({13, 7}));
  EXPECT_EQ(j["resolution_px"], nlohmann::json::array({146, 78}));
  EXPECT_NEAR(j["fov_deg"][0].get<double>(), 29.1, 0.05);
  EXPECT_NEAR(j["fov_deg"][1].get<double>(), 15.9, 0.05);
  EXPECT_NEAR(j["eye_box_mm"].get<double>(), 7.58, 5e-3);
  EXPECT_NEAR(j["gap_mm"].get<double>(), 3.289, 5e-4);
  EXPECT_NEAR(j["magnification"].get<double>(), 296.5, 0.05);
  EXPECT_NEAR(j["elemental_image_mm"].get<double>(), 1.1316, 5e-5);
  EXPECT_EQ(j["views"], 4);
  ASSERT_EQ(j["depth_of_field_mm"].size(), 2u);
  EXPECT_TRUE(j["depth_of_field_mm"][1].is_null());
  for (const char* nm : {"390", "550", "780"}) EXPECT_TRUE(j["diffraction_pitch_um"][nm].is_number()) << nm;
  EXPECT_TRUE(j["simple_magnifier_min_focal_mm"].is_number());
}

TEST(DesignCli, StockProfileGivesNulls) {
  const auto r = run_nelf("design --profile hmz-t1-stock --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = parse_one_object(r.out);
  EXPECT_EQ(j["profile"], "hmz-t1-stock");
  for (const char* key : {"gap_mm", "magnification", "elemental_image_mm", "eye_box_mm", "views"})
    EXPECT_TRUE(j[key].is_null()) << key;
  for (const char* key : {"lenses", "fov_deg", "resolution_px", "depth_of_field_mm"})
    EXPECT_TRUE(j[key][0].is_null() && j[key][1].is_null()) << key;
  EXPECT_TRUE(j["diffraction_pitch_um"]["390"].is_null());
  EXPECT_EQ(j["display"]["resolution_px"], nlohmann::json::array({1280, 720}));
}

TEST(DesignCli, MagnifierProfileFileGivesFigures) {
  test::TempDir dir;
  const auto file = dir / "loupe.toml";
  test::write_file(file, R"(name = "loupe"
[display]
resolution = [1600, 1200]
pixel_pitch_mm = 0.01
[magnifier]
width_mm = 20.0
focal_length_mm = 40.0
[viewing]
eye_relief_mm = 20.0
virtual_image_mm = 2000.0
)");
  const auto r = run_nelf("design --json --profile " + q(file));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = parse_one_object(r.out);
  EXPECT_EQ(j["profile"], "loupe");
  EXPECT_EQ(j["lenses"], nlohmann::json::array({1, 1}));
  EXPECT_EQ(j["resolution_px"], nlohmann::json::array({1600, 1200}));
  EXPECT_NEAR(j["fov_deg"][0].get<double>(), 22.840148, 1e-5);  // by hand in test_optics.cpp
  EXPECT_NEAR(j["eye_box_mm"].get<double>(), 12.040404, 1e-6);
  EXPECT_NEAR(j["elemental_image_mm"].get<double>(), 16.0, 1e-12);
  for (const char* key : {"gap_mm", "magnification", "views"}) EXPECT_TRUE(j[key].is_number()) << key;
  EXPECT_TRUE(j["diffraction_pitch_um"]["550"].is_number());
}

TEST(DesignCli, TableMentionsTheKeyFigures) {
  const auto r = run_nelf("design");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* s : {"hmz-t1", "field of view", "29.1", "15.9", "resolution", "146", "78", "eye box", "7.58",
                        "3.289", "296.5", "1.1316", "views", "pixel pitch", "15.36 × 8.64 mm"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
}

TEST(DesignCli, PlotWritesAPngOfSensibleSize) {
  test::TempDir dir;
  const auto png = dir / "trade space.png";
  const auto r = run_nelf("design --plot " + q(png));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("146"), std::string::npos);  // the table is still printed
  OIIO::ImageBuf image(png.string());
  ASSERT_TRUE(image.read()) << image.geterror();
  EXPECT_EQ(image.spec().format, OIIO::TypeDesc::UINT8);
  EXPECT_GE(image.spec().width, 800);
  EXPECT_LE(image.spec().width, 4000);
  EXPECT_GE(image.spec().height, 600);
  EXPECT_LE(image.spec().height, 4000);
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1u);  // no temporary file left behind
}

TEST(DesignCli, UnwritablePlotPathFailsCleanly) {
  test::TempDir dir;
  const auto png = dir / "no-such-dir" / "plot.png";
  const auto r = run_nelf("design --plot " + q(png));
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find(png.string()), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

// --- bad profiles -------------------------------------------------------------------------------

struct BadProfile {
  std::string name;
  std::string file_text;              // empty: the file does not exist
  std::vector<std::string> expected;  // substrings of the one error line
};

void expect_profile_error(const BadProfile& bad) {
  test::TempDir dir;
  const auto file = dir / (bad.name + ".toml");
  if (!bad.file_text.empty()) test::write_file(file, bad.file_text);
  const auto r = run_nelf("design --profile " + q(file));
  EXPECT_EQ(r.status, 2) << bad.name << ": " << r.err;
  EXPECT_EQ(r.out, "") << bad.name;
  EXPECT_EQ(count_lines(r.err), 1u) << bad.name << ": " << r.err;
  EXPECT_NE(r.err.find(file.string()), std::string::npos) << bad.name << ": " << r.err;
  for (const auto& s : bad.expected) EXPECT_NE(r.err.find(s), std::string::npos) << bad.name << ": " << r.err;
}

std::string with(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("test profile has no '" + from + "'");
  return text.replace(at, from.size(), to);
}

TEST(DesignCliBadProfile, MissingFile) { expect_profile_error({"missing", "", {"no such file"}}); }

TEST(DesignCliBadProfile, SyntaxErrorNamesTheLine) {
  expect_profile_error({"syntax", with(valid_lens_profile, "[lens_array]", "[lens_array"), {".toml:5:", "syntax"}});
}

TEST(DesignCliBadProfile, UnknownKeySuggestsTheNearest) {
  expect_profile_error({"unknown",
                        with(valid_lens_profile, "focal_length_mm", "focal_lenght_mm"),
                        {"lens_array.focal_lenght_mm", "did you mean lens_array.focal_length_mm"}});
}

TEST(DesignCliBadProfile, WrongType) {
  expect_profile_error({"type",
                        with(valid_lens_profile, "eye_relief_mm = 25.0", "eye_relief_mm = \"near\""),
                        {"viewing.eye_relief_mm", "must be a number", "\"near\""}});
}

TEST(DesignCliBadProfile, NonPositivePitch) {
  expect_profile_error({"pitch",
                        with(valid_lens_profile, "pitch_mm = 1.0", "pitch_mm = 0"),
                        {"lens_array.pitch_mm must be > 0, got 0"}});
  expect_profile_error({"pixel",
                        with(valid_lens_profile, "pixel_pitch_mm = 0.012", "pixel_pitch_mm = -0.01"),
                        {"display.pixel_pitch_mm must be > 0, got -0.01"}});
}

TEST(DesignCliBadProfile, NonPositiveFocalLength) {
  expect_profile_error({"focal",
                        with(valid_lens_profile, "focal_length_mm = 3.3", "focal_length_mm = -3"),
                        {"lens_array.focal_length_mm must be > 0, got -3"}});
}

TEST(DesignCliBadProfile, NonPositiveResolution) {
  expect_profile_error({"resolution",
                        with(valid_lens_profile, "[1280, 720]", "[1280, 0]"),
                        {"display.resolution", "between 1 and 16384"}});
}

TEST(DesignCliBadProfile, VirtualImageInsideEyeReliefPlusFocalLength) {
  expect_profile_error({"image",
                        with(valid_lens_profile, "virtual_image_mm = 1000.0", "virtual_image_mm = 28.3"),
                        {"viewing.virtual_image_mm", "eye_relief_mm + lens_array.focal_length_mm", "28.3"}});
}

TEST(DesignCliBadProfile, LensPitchWiderThanDisplay) {
  expect_profile_error({"wide",
                        with(valid_lens_profile, "pitch_mm = 1.0", "pitch_mm = 9"),
                        {"lens_array.pitch_mm", "display's smaller side", "got 9"}});
}

// Absurd but formerly accepted profiles (issue #11): 16384 mm pixels made millions of lenses and hung
// convert; 1e9 overflowed the lens count (design printed -2147483648 lenses and a -180 deg field of
// view). Refused with one line naming the file and the key, like every profile error.
TEST(DesignCliBadProfile, AbsurdPixelPitchIsRefused) {
  for (const char* pitch : {"16384", "1e9"})
    expect_profile_error({"pixel-pitch",
                          with(valid_lens_profile, "pixel_pitch_mm = 0.012", std::string("pixel_pitch_mm = ") + pitch),
                          {"display.pixel_pitch_mm", "at most 1000 mm a side"}});
}

TEST(DesignCliBadProfile, ExtremeValuesAreRefused) {
  const struct {
    const char *from, *to, *key;
  } cases[] = {
      {"pixel_pitch_mm = 0.012", "pixel_pitch_mm = 0", "display.pixel_pitch_mm"},
      {"pixel_pitch_mm = 0.012", "pixel_pitch_mm = -1e9", "display.pixel_pitch_mm"},
      {"pixel_pitch_mm = 0.012", "pixel_pitch_mm = nan", "display.pixel_pitch_mm"},
      {"pixel_pitch_mm = 0.012", "pixel_pitch_mm = inf", "display.pixel_pitch_mm"},
      {"pixel_pitch_mm = 0.012", "pixel_pitch_mm = 1e-9", "display.pixel_pitch_mm"},
      {"pitch_mm = 1.0", "pitch_mm = 0.001", "lens_array.pitch_mm"},
      {"focal_length_mm = 3.3", "focal_length_mm = 3.3\ngap_mm = 1e300", "lens_array.gap_mm"},
      {"focal_length_mm = 3.3", "focal_length_mm = nan", "lens_array.focal_length_mm"},
      {"eye_relief_mm = 25.0", "eye_relief_mm = 1e-300", "viewing.eye_relief_mm"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = inf", "viewing.virtual_image_mm"},
      {"virtual_image_mm = 1000.0", "virtual_image_mm = 1000.0\npupil_mm = 1e300", "viewing.pupil_mm"},
  };
  for (const auto& c : cases) expect_profile_error({"extreme", with(valid_lens_profile, c.from, c.to), {c.key}});
}

TEST(DesignCli, UnknownBuiltinListsTheBuiltins) {
  const auto r = run_nelf("design --profile hmz-t2");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  for (const char* s : {"hmz-t2", "hmz-t1", "hmz-t1-stock"}) EXPECT_NE(r.err.find(s), std::string::npos) << r.err;
}

TEST(DesignCli, ValidProfileFileWorks) {
  test::TempDir dir;
  const auto file = dir / "custom.toml";
  test::write_file(file, valid_lens_profile);
  const auto r = run_nelf("design --json --profile " + q(file));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(parse_one_object(r.out)["resolution_px"], nlohmann::json::array({146, 78}));
}

// --- the rest of the CLI surface -----------------------------------------------------------------

TEST(ProfilesCli, ListsEachBuiltinWithItsDescriptionInAColumn) {
  const auto r = run_nelf("profiles");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(count_lines(r.out), 4u) << r.out;
  // Every description starts in the same column, past the longest name (ii-2160-testbed).
  std::size_t column = 0;
  for (const char* name : {"hmz-t1 ", "hmz-t1-stock ", "ii-2160-testbed ", "lvt-prototype "}) {
    const auto at = r.out.find(name);
    ASSERT_NE(at, std::string::npos) << name << "\n" << r.out;
    const auto line_start = r.out.rfind('\n', at) == std::string::npos ? 0 : r.out.rfind('\n', at) + 1;
    const auto description = r.out.find_first_not_of(' ', at + std::string(name).size() - 1) - line_start;
    if (column == 0) column = description;
    EXPECT_EQ(description, column) << name << "\n" << r.out;
  }
  EXPECT_EQ(column, std::string("ii-2160-testbed ").size());
}

TEST(Cli, Version) {
  const auto r = run_nelf("--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out, std::string("nelf ") + NELF_VERSION + "\n");
}

TEST(Cli, HelpForDesignAndProfiles) {
  const auto design = run_nelf("design --help");
  EXPECT_EQ(design.status, 0);
  for (const char* s : {"--profile", "--json", "--plot"})
    EXPECT_NE(design.out.find(s), std::string::npos) << s << "\n" << design.out;
  const auto profiles = run_nelf("profiles --help");
  EXPECT_EQ(profiles.status, 0);
  EXPECT_NE(profiles.out.find("built-in"), std::string::npos) << profiles.out;
}

TEST(Cli, UnknownOptionIsAUsageError) {
  const auto r = run_nelf("design --jsn");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
}

}  // namespace
}  // namespace nelf
