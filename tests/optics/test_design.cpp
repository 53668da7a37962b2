// The design report (optics/design.hpp) and the trade-space plot (analysis/design_plot.hpp).
// Expected values come from DESIGN.md §2 (hmz-t1) and from the hand computations in test_optics.cpp.
#include <gtest/gtest.h>

#include <OpenImageIO/imagebuf.h>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "analysis/design_plot.hpp"
#include "optics/design.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

// The hand geometry of test_optics.cpp as a profile: 16 × 12 mm panel, 2 mm / f 5 mm lenses,
// d_e 20 mm, d_o 500 mm.
const char* hand_profile = R"(
name = "hand"
[display]
resolution = [1600, 1200]
pixel_pitch_mm = 0.01
[lens_array]
pitch_mm = 2.0
focal_length_mm = 5.0
[viewing]
eye_relief_mm = 20.0
virtual_image_mm = 500.0
pupil_mm = 4.0
[magnifier_comparison]
eye_box_mm = 8.0
f_number = 2.0
)";

// The hand magnifier of test_optics.cpp: 20 mm wide, f = 40 mm, d_e 20 mm, d_o 2000 mm.
const char* magnifier_profile = R"(
name = "loupe"
[display]
resolution = [1600, 1200]
pixel_pitch_mm = 0.01
[magnifier]
width_mm = 20.0
focal_length_mm = 40.0
[viewing]
eye_relief_mm = 20.0
virtual_image_mm = 2000.0
)";

TEST(DesignReport, HmzT1MatchesDesignTable) {
  const DesignReport r = design_report(load_profile("hmz-t1"));
  EXPECT_EQ(r.profile, "hmz-t1");
  EXPECT_EQ(r.kind, DesignOptics::lens_array);
  ASSERT_TRUE(r.optics);
  const OpticalDesign& o = *r.optics;
  EXPECT_NEAR(o.gap_mm, 3.289, 5e-4);
  EXPECT_NEAR(o.magnification, 296.5, 0.05);
  EXPECT_NEAR(o.axis[0].elemental_image_mm, 1.1316, 5e-5);
  EXPECT_EQ(o.axis[0].lenses, 13);
  EXPECT_EQ(o.axis[1].lenses, 7);
  EXPECT_NEAR(o.axis[0].fov_deg, 29.1, 0.05);
  EXPECT_NEAR(o.axis[1].fov_deg, 15.9, 0.05);
  EXPECT_EQ(o.axis[0].resolution_px, 146);
  EXPECT_EQ(o.axis[1].resolution_px, 78);
  EXPECT_NEAR(o.axis[0].eye_box_mm, 7.58, 5e-3);
  EXPECT_EQ(o.views, 4);
  EXPECT_FALSE(o.axis[0].depth_of_field.far_mm);
  EXPECT_NEAR(o.diffraction_pitch_um[1], 550e-3 * o.gap_mm / 1.0, 1e-12);
  // App. A at f/1 with a 10 mm eye box (the defaults), display width 15.36 mm, d_e 25 mm.
  EXPECT_NEAR(r.simple_magnifier_min_focal_mm, (10 + std::sqrt(100 + 4 * 25 * 15.36)) / 2, 1e-9);
  EXPECT_EQ(r.panel_px[0], 1280);
  EXPECT_NEAR(r.display_mm.y, 8.64, 1e-12);
}

TEST(DesignReport, HandGeometryWithEvenLensCounts) {
  const DesignReport r = design_report(parse_profile(hand_profile, "hand.toml"));
  ASSERT_TRUE(r.optics);
  const OpticalDesign& o = *r.optics;
  EXPECT_NEAR(o.gap_mm, 5.0 * 480 / 485, 1e-12);
  EXPECT_NEAR(o.magnification, 97.0, 1e-12);
  EXPECT_EQ(o.axis[0].lenses, 6);
  EXPECT_EQ(o.axis[1].lenses, 4);
  EXPECT_EQ(o.axis[0].resolution_px, 309);
  EXPECT_EQ(o.axis[1].resolution_px, 206);
  EXPECT_NEAR(o.axis[0].fov_deg, 33.39849, 1e-4);
  EXPECT_NEAR(o.axis[0].eye_box_mm, 8.0, 1e-9);
  EXPECT_NEAR(o.axis[0].depth_of_field.near_mm, 5097.0 / 14.85, 1e-9);
  ASSERT_TRUE(o.axis[0].depth_of_field.far_mm);
  EXPECT_NEAR(*o.axis[0].depth_of_field.far_mm, 4903.0 / 5.15, 1e-9);
  EXPECT_EQ(o.views, 2);
  // [magnifier_comparison] f/2, eye box 8 mm: (16 + √2816)/2.
  EXPECT_NEAR(r.simple_magnifier_min_focal_mm, (16 + std::sqrt(2816.0)) / 2, 1e-9);
}

TEST(DesignReport, FixedGapIsUsedAsGiven) {
  std::string text = hand_profile;
  text.replace(text.find("focal_length_mm = 5.0"), 21, "focal_length_mm = 5.0\ngap_mm = 4.5");
  const DesignReport r = design_report(parse_profile(text, "gap.toml"));
  ASSERT_TRUE(r.optics);
  EXPECT_DOUBLE_EQ(r.optics->gap_mm, 4.5);
  EXPECT_NEAR(r.optics->magnification, 5.0 / 0.5, 1e-12);  // thin lens: f/(f − d_l)
  EXPECT_NEAR(r.optics->axis[0].elemental_image_mm, 24.5 / 20 * 2, 1e-12);
}

TEST(DesignReport, StockProfileReportsOnlyThePanel) {
  const DesignReport r = design_report(load_profile("hmz-t1-stock"));
  EXPECT_EQ(r.kind, DesignOptics::none);
  EXPECT_FALSE(r.optics);
  EXPECT_EQ(r.panel_px[1], 720);
  EXPECT_NEAR(r.display_mm.x, 15.36, 1e-12);
  EXPECT_GT(r.simple_magnifier_min_focal_mm, 0.0);
}

TEST(DesignReport, MagnifierUsesTheSingleLensModel) {
  const DesignReport r = design_report(parse_profile(magnifier_profile, "loupe.toml"));
  EXPECT_EQ(r.kind, DesignOptics::magnifier);
  ASSERT_TRUE(r.optics);
  const OpticalDesign& o = *r.optics;
  EXPECT_EQ(o.axis[0].lenses, 1);
  EXPECT_EQ(o.axis[1].lenses, 1);
  EXPECT_DOUBLE_EQ(o.axis[0].elemental_image_mm, 16.0);
  EXPECT_DOUBLE_EQ(o.axis[1].elemental_image_mm, 12.0);
  EXPECT_NEAR(o.gap_mm, 40.0 * 1980 / 2020, 1e-12);
  EXPECT_NEAR(o.magnification, 50.5, 1e-12);
  EXPECT_NEAR(o.axis[0].fov_deg, 22.840148, 1e-5);
  EXPECT_NEAR(o.axis[1].fov_deg, 17.229599, 1e-5);
  EXPECT_EQ(o.axis[0].resolution_px, 1600);
  EXPECT_EQ(o.axis[1].resolution_px, 1200);
  EXPECT_NEAR(o.axis[0].eye_box_mm, 12.040404040, 1e-8);
  EXPECT_EQ(o.views, 1);
}

TEST(DesignJson, HasEveryKeyWithHmzT1Values) {
  const nlohmann::json j = design_to_json(design_report(load_profile("hmz-t1")));
  for (const char* key :
       {"profile", "gap_mm", "magnification", "elemental_image_mm", "lenses", "fov_deg", "resolution_px", "eye_box_mm",
        "depth_of_field_mm", "views", "diffraction_pitch_um", "simple_magnifier_min_focal_mm", "display"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["profile"], "hmz-t1");
  EXPECT_EQ(j["lenses"], nlohmann::json::array({13, 7}));
  EXPECT_EQ(j["resolution_px"], nlohmann::json::array({146, 78}));
  EXPECT_NEAR(j["fov_deg"][0].get<double>(), 29.1, 0.05);
  EXPECT_NEAR(j["eye_box_mm"].get<double>(), 7.58, 5e-3);
  EXPECT_EQ(j["views"], 4);
  EXPECT_TRUE(j["depth_of_field_mm"][0].is_number());
  EXPECT_TRUE(j["depth_of_field_mm"][1].is_null());
  for (const char* nm : {"390", "550", "780"}) EXPECT_TRUE(j["diffraction_pitch_um"][nm].is_number()) << nm;
  EXPECT_EQ(j["display"]["resolution_px"], nlohmann::json::array({1280, 720}));
}

TEST(DesignJson, StockHasNullOptics) {
  const nlohmann::json j = design_to_json(design_report(load_profile("hmz-t1-stock")));
  for (const char* key : {"gap_mm", "magnification", "elemental_image_mm", "eye_box_mm", "views"})
    EXPECT_TRUE(j[key].is_null()) << key;
  for (const char* key : {"lenses", "fov_deg", "resolution_px", "depth_of_field_mm"}) {
    ASSERT_TRUE(j[key].is_array()) << key;
    EXPECT_TRUE(j[key][0].is_null() && j[key][1].is_null()) << key;
  }
  EXPECT_TRUE(j["diffraction_pitch_um"]["550"].is_null());
  EXPECT_TRUE(j["simple_magnifier_min_focal_mm"].is_number());
  EXPECT_EQ(j["display"]["size_mm"][0], 15.36);
}

TEST(DesignJson, FiniteDepthOfFieldHasBothEnds) {
  const nlohmann::json j = design_to_json(design_report(parse_profile(hand_profile, "hand.toml")));
  EXPECT_NEAR(j["depth_of_field_mm"][1].get<double>(), 4903.0 / 5.15, 1e-9);
}

TEST(DesignTable, ShowsTheKeyFigures) {
  const std::string t = design_table(design_report(load_profile("hmz-t1")));
  for (const char* s :
       {"hmz-t1", "1280 × 720", "3.289", "296.5", "1.1316", "29.1", "15.9", "146", "78", "7.58", "238.9", "∞", "25.22"})
    EXPECT_NE(t.find(s), std::string::npos) << s << "\n" << t;
  // Aligned: the unit column starts at the same display column on every row, so all rows ending in
  // the unit "mm" are equally wide (counting code points: "Δ" and "∞" are one column each).
  const auto columns = [](const std::string& s) {
    std::size_t n = 0;
    for (unsigned char c : s) n += (c & 0xC0) != 0x80;
    return n;
  };
  std::size_t width = 0;
  int mm_rows = 0;
  std::istringstream lines(t.substr(t.find("quantity")));
  for (std::string line; std::getline(lines, line) && !line.empty();) {
    if (line.size() < 3 || line.compare(line.size() - 3, 3, " mm") != 0) continue;
    if (width == 0) width = columns(line);
    EXPECT_EQ(columns(line), width) << line;
    ++mm_rows;
  }
  EXPECT_EQ(mm_rows, 6);  // gap, elemental image, eye box, depth of field ×2, App. A
}

TEST(DesignTable, StockSaysWhyFiguresAreMissing) {
  const std::string t = design_table(design_report(load_profile("hmz-t1-stock")));
  EXPECT_NE(t.find("—"), std::string::npos);
  EXPECT_NE(t.find("[magnifier]"), std::string::npos);
}

TEST(DesignPlot, TradeSpaceAgreesWithTheReportAtTheDesignPoint) {
  const Profile p = load_profile("hmz-t1");
  EXPECT_EQ(trade_space_resolution_px(p, 3.3, 1.0), 146);
  // Longer focal lengths magnify less and resolve more (Eq. 8 ∝ 1/M).
  EXPECT_GT(trade_space_resolution_px(p, 9.0, 1.0), trade_space_resolution_px(p, 2.0, 1.0));
}

TEST(DesignPlot, WritesAReadablePngAndNoTemporaryFile) {
  test::TempDir dir;
  const auto path = dir / "trade.png";
  write_trade_space_plot(load_profile("hmz-t1"), path);
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 1);

  OIIO::ImageBuf image(path.string());
  ASSERT_TRUE(image.read()) << image.geterror();
  EXPECT_GE(image.spec().width, 800);
  EXPECT_GE(image.spec().height, 600);
  EXPECT_EQ(image.spec().nchannels, 3);
  // N_p grows with f: near the bottom of the plot (small w_l), the right end (f ≈ 9.5 mm,
  // N_p ≈ 350) is drawn much brighter than the left end (f ≈ 1.25 mm, N_p ≈ 60) in viridis.
  const int y = image.spec().height * 85 / 100;
  std::array<float, 3> dim{}, bright{};
  image.getpixel(image.spec().width * 12 / 100, y, dim.data(), 3);
  image.getpixel(image.spec().width * 78 / 100, y, bright.data(), 3);
  EXPECT_LT(dim[1], 0.35f);
  EXPECT_GT(bright[1], 0.7f);
}

TEST(DesignPlot, StockProfileIsPlottedWithoutMark) {
  test::TempDir dir;
  const auto path = dir / "stock.png";
  EXPECT_NO_THROW(write_trade_space_plot(load_profile("hmz-t1-stock"), path));
  EXPECT_TRUE(std::filesystem::is_regular_file(path));
}

TEST(DesignPlot, UnwritablePathThrowsAndLeavesNothing) {
  test::TempDir dir;
  EXPECT_THROW(write_trade_space_plot(load_profile("hmz-t1"), dir / "missing" / "p.png"), PlotError);
  EXPECT_THROW(write_trade_space_plot(load_profile("hmz-t1"), dir / "p.unknown-format"), PlotError);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace nelf
