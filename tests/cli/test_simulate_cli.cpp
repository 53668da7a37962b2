#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "support/test_support.hpp"

namespace nelf::test {
namespace {

// hmz-t1 optics with a quarter of its pixels per axis (4× the pitch): same lens block, field of view and
// eye box, fast enough for a CLI test. `extra` is appended (e.g. a calibration table).
std::string small_profile(const std::string& extra = "") {
  return R"(
name = "small"
[display]
resolution = [320, 180]
pixel_pitch_mm = 0.048
[lens_array]
pitch_mm = 1.0
focal_length_mm = 3.3
[viewing]
eye_relief_mm = 25.0
virtual_image_mm = 1000.0
pupil_mm = 4.0
ipd_mm = 63.0
)" + extra;
}

// A 256×144 PNG with blocks, a ramp and rings: detail the small display can just resolve.
void write_test_still(const std::filesystem::path& path) {
  const int w = 256, h = 144;
  std::vector<unsigned char> pixels(static_cast<std::size_t>(w * h * 3));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double u = (x + 0.5) / w, t = (y + 0.5) / h;
      const bool block = (static_cast<int>(u * 8) + static_cast<int>(t * 4.5)) % 2 == 0;
      const double ring = std::hypot((u - 0.5) * 16.0 / 9.0, t - 0.5);
      unsigned char* p = &pixels[static_cast<std::size_t>((y * w + x) * 3)];
      p[0] = block ? 204 : 51;
      p[1] = static_cast<unsigned char>(51 + 153 * u);
      p[2] = static_cast<unsigned char>(127.5 + 127 * std::cos(2 * std::numbers::pi * ring * 3));
    }
  }
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out);
  ASSERT_TRUE(out->open(path.string(), OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
  ASSERT_TRUE(out->close());
}

struct Fixture {
  TempDir dir;
  std::filesystem::path still = dir / "still.png";
  std::filesystem::path profile = dir / "small.toml";
  std::filesystem::path retina = dir / "retina.png";
  Fixture(const std::string& profile_extra = "") {
    write_test_still(still);
    write_file(profile, small_profile(profile_extra));
  }
  // `nelf simulate STILL --profile small.toml -o retina.png ARGS`
  CommandResult simulate(const std::string& args) const {
    return run_nelf("simulate " + q(still) + " --profile " + q(profile) + " -o " + q(retina) + " " + args);
  }
  double psnr(const std::string& args) const {
    const CommandResult r = simulate("--json " + args);
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(r.out).at("psnr_db").get<double>();
  }
};

// One line on stderr, prefixed like every nelf error, non-zero exit.
void expect_one_line_error(const CommandResult& r, const std::string& fragment) {
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("nelf: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

std::array<int, 2> image_size(const std::filesystem::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) return {0, 0};
  return {in->spec().width, in->spec().height};
}

TEST(SimulateCli, JsonSchemaAndRetinalImage) {
  Fixture f;
  const CommandResult r = f.simulate("--json --ideal " + q(f.dir / "ideal.png"));
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "exactly one line of JSON: " << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.is_object());
  ASSERT_TRUE(j.at("psnr_db").is_number());
  EXPECT_GT(j["psnr_db"].get<double>(), 25.0);               // measured 30.0 dB
  EXPECT_DOUBLE_EQ(j.at("focus_mm").get<double>(), 1000.0);  // default: the screen distance
  EXPECT_DOUBLE_EQ(j.at("pupil_mm").get<double>(), 4.0);     // default: viewing.pupil_mm
  EXPECT_EQ(j.at("eye"), "left");
  const auto size = j.at("retina_size").get<std::array<int, 2>>();
  EXPECT_EQ(image_size(f.retina), size);
  EXPECT_EQ(image_size(f.dir / "ideal.png"), size);
  EXPECT_GT(size[0], size[1]);  // the screen is 16:9, upright
  // Nothing left behind but the requested files.
  int files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(f.dir.path())) ++files;
  EXPECT_EQ(files, 4);
}

TEST(SimulateCli, FocusPupilAndEyeOptions) {
  Fixture f;
  CommandResult r = f.simulate("--json --focus-mm 250 --pupil-mm 3 --eye right --eye-offset-mm 0.5,-0.25");
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j.at("focus_mm").get<double>(), 250.0);
  EXPECT_DOUBLE_EQ(j.at("pupil_mm").get<double>(), 3.0);
  EXPECT_EQ(j.at("eye"), "right");
  EXPECT_EQ(j.at("eye_offset_mm"), nlohmann::json({0.5, -0.25}));
  r = f.simulate("--json --focus-mm inf");
  ASSERT_EQ(r.status, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j.at("focus_mm").is_null());  // focused at infinity
  EXPECT_TRUE(j.at("psnr_db").is_number());
  r = f.simulate("");  // human-readable summary
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("PSNR ", 0), 0u) << r.out;
}

TEST(SimulateCli, MiscalibratedRenderingLosesPsnr) {
  // The rendering is calibrated for a sheet shifted by half an elemental image (1.1316 mm / 0.048 mm / 2
  // = 11.8 px) while the simulated hardware is the nominal one: the eye looks into the wrong views.
  const double aligned = Fixture().psnr("");
  const double misaligned = Fixture("[calibration.left]\nshift_px = [11.8, 0.0]\n").psnr("");
  EXPECT_LT(misaligned, aligned - 10.0) << "aligned " << aligned << " dB";
}

TEST(SimulateCli, EyeFarOutsideTheEyeBoxDegrades) {
  Fixture f;
  const double centred = f.psnr("");
  EXPECT_GT(f.psnr("--eye-offset-mm 1,0"), centred - 4.0);
  EXPECT_LT(f.psnr("--eye-offset-mm 8,0"), centred - 15.0);
}

// Pixels of the zone of comfort's red (no viridis colour is near it) in an 8-bit RGB image.
int red_pixels(const std::filesystem::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) return -1;
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<unsigned char> pixels(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, pixels.data())) return -1;
  int red = 0;
  for (std::size_t k = 0; k + 2 < pixels.size(); k += spec.nchannels)
    red += pixels[k] > 200 && pixels[k + 1] < 60 && pixels[k + 2] < 60 ? 1 : 0;
  return red;
}

// The table's cells by (screen diopters, accommodation diopters): each row's named columns.
std::map<std::pair<std::string, std::string>, std::map<std::string, std::string>> sweep_cells(
    const std::string& table) {
  std::istringstream lines(table);
  std::string line;
  std::getline(lines, line);
  std::vector<std::string> header;
  for (std::istringstream h(line); std::getline(h, line, ',');) header.push_back(line);
  std::map<std::pair<std::string, std::string>, std::map<std::string, std::string>> cells;
  while (std::getline(lines, line)) {
    std::map<std::string, std::string> cell;
    std::istringstream fields(line);
    for (const std::string& name : header) std::getline(fields, cell[name], ',');
    cells[{cell["screen_diopters"], cell["accommodation_diopters"]}] = cell;
  }
  return cells;
}

TEST(SimulateCli, SweepWritesTableAndHeatmap) {
  Fixture f;
  const auto csv = f.dir / "sweep.csv";
  const CommandResult r = f.simulate("--json --sweep " + q(csv));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string table = read_file(csv);
  EXPECT_EQ(table.rfind("screen_diopters,screen_mm,accommodation_diopters,accommodation_mm,psnr_db", 0), 0u);
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 1 + 9 * 17);  // 9 screen distances × 17 accommodations
  EXPECT_NE(table.find("\n1,1000.0,0,inf,"), std::string::npos) << "infinity row for the 1 m screen";
  EXPECT_NE(table.find("\n4,250.0,4,250.0,"), std::string::npos);
  const auto heatmap = image_size(f.dir / "sweep.png");
  EXPECT_GT(heatmap[0], 600);
  EXPECT_GT(heatmap[1], 300);
  EXPECT_GT(red_pixels(f.dir / "sweep.png"), 2 * 9 * 34) << "the zone's two edges, a row's height each";

  // Each cell says whether its accommodation is comfortable with the eyes converged on the screen
  // (Shibata et al. 2011): converged at 1 m, from 0.49 D to 1.57 D; at 4 m from infinity to 0.85 D.
  const auto cells = sweep_cells(table);
  ASSERT_EQ(cells.size(), 9u * 17u);
  const auto in_zone = [&](const char* screen, const char* accommodation) {
    return cells.at({screen, accommodation}).at("comfort_zone");
  };
  EXPECT_EQ(in_zone("1", "0.25"), "0");
  EXPECT_EQ(in_zone("1", "0.5"), "1");
  EXPECT_EQ(in_zone("1", "1.5"), "1");
  EXPECT_EQ(in_zone("1", "1.75"), "0");
  EXPECT_EQ(in_zone("0.25", "0"), "1");
  EXPECT_EQ(in_zone("0.25", "0.75"), "1");
  EXPECT_EQ(in_zone("0.25", "1"), "0");
  EXPECT_EQ(in_zone("4", "3"), "0");
  EXPECT_EQ(in_zone("4", "3.25"), "1");
  // Without --depth the flat screen is what was simulated: no gain, and no gain heatmap.
  for (const auto& [at, cell] : cells) EXPECT_EQ(cell.at("psnr_flat_db"), cell.at("psnr_db"));
  EXPECT_FALSE(std::filesystem::exists(f.dir / "sweep.gain.png"));
}

// Against the real scene (a synthetic scene, refilmed for each screen distance) the sweep shows what
// following the content's depth gains: each cell also on the flat screen, the difference in the
// table and in a heatmap of its own. The flat cells are the --depth off sweep's.
TEST(SimulateCli, SweepAgainstTheRealSceneShowsTheDepthAwareGain) {
  Fixture f;
  const std::string planes =
      "simulate synthetic:scene=planes,size=320x180 --profile " + q(f.profile) + " -o " + q(f.retina);
  const auto depth_csv = f.dir / "depth.csv", flat_csv = f.dir / "flat.csv";
  CommandResult r = run_nelf(planes + " --depth auto --sweep " + q(depth_csv));
  ASSERT_EQ(r.status, 0) << r.err;
  r = run_nelf(planes + " --depth off --sweep " + q(flat_csv));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto with_depth = sweep_cells(read_file(depth_csv)), flat = sweep_cells(read_file(flat_csv));
  ASSERT_EQ(with_depth.size(), 9u * 17u);
  ASSERT_EQ(flat.size(), with_depth.size());
  int differ = 0;
  for (const auto& [at, cell] : with_depth) {
    EXPECT_EQ(cell.at("psnr_flat_db"), flat.at(at).at("psnr_db"));
    const double gain = std::stod(cell.at("gain_db"));
    EXPECT_NEAR(gain, std::stod(cell.at("psnr_db")) - std::stod(cell.at("psnr_flat_db")), 0.002);
    differ += std::abs(gain) > 0.05 ? 1 : 0;
  }
  EXPECT_GT(differ, 100) << "the depth-aware composite is not the flat one";
  // The screen at 4 m, the eye on the near plane (250 mm): the flat screen blurs it, depth keeps it
  // (measured +1.64 dB on this coarse panel; hmz-t1's own is +5.3 dB).
  EXPECT_GT(std::stod(with_depth.at({"0.25", "4"}).at("gain_db")), 0.8);
  EXPECT_GT(image_size(f.dir / "depth.gain.png")[0], 600);
  EXPECT_FALSE(std::filesystem::exists(f.dir / "flat.gain.png"));
}

// The sweep shows the panel the single simulation shows: with a defect map, the defects in every
// row, compensated unless --no-defect-compensation (the map planned for each screen distance).
TEST(SimulateCli, SweepShowsThePanelsDefects) {
  const auto psnr_at_the_screen = [](const Fixture& f, const std::string& args) {
    const auto csv = f.dir / "sweep.csv";
    const CommandResult r = f.simulate("--sweep " + q(csv) + " " + args);
    EXPECT_EQ(r.status, 0) << r.err;
    const std::string table = read_file(csv);
    const std::string row = "\n1,1000.0,1,1000.0,";  // the 1 m screen, the eye focused on it
    const std::size_t at = table.find(row);
    if (at == std::string::npos) {
      ADD_FAILURE() << table;
      return 0.0;
    }
    return std::stod(table.substr(at + row.size()));
  };
  std::string map;  // about 1 % of the left panel's pixels dead, spread so that every bundle keeps healthy pixels
  for (int y = 3; y < 180; y += 9)
    for (int x = 5 + (y % 2) * 6; x < 320; x += 11) map += fmt::format("left {} {} dead\n", x, y);
  const Fixture clean;
  Fixture with_map("[correction]\ndefect_map = \"panel.defects\"\n");
  write_file(with_map.dir / "panel.defects", map);
  const double defect_free = psnr_at_the_screen(clean, "");
  const double uncompensated = psnr_at_the_screen(with_map, "--no-defect-compensation");
  const double compensated = psnr_at_the_screen(with_map, "");
  EXPECT_LT(uncompensated, defect_free - 0.4);  // measured 28.87 dB against 29.63 (the small panel's resolution rules)
  EXPECT_GT(compensated, uncompensated + 0.3);  // measured 29.41 dB
  EXPECT_LT(compensated, defect_free);
}

TEST(SimulateCli, UnreadableImage) {
  Fixture f;
  write_file(f.still, "this is not an image");
  expect_one_line_error(f.simulate(""), "cannot read the image");
  EXPECT_FALSE(std::filesystem::exists(f.retina));
  std::filesystem::remove(f.still);
  expect_one_line_error(f.simulate(""), "no such file");
  EXPECT_FALSE(std::filesystem::exists(f.retina));
}

TEST(SimulateCli, BadEyeValue) {
  Fixture f;
  const CommandResult r = f.simulate("--eye middle");
  expect_one_line_error(r, "--eye");
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(std::filesystem::exists(f.retina));
}

TEST(SimulateCli, BadEyeOffsetSyntax) {
  Fixture f;
  for (const char* bad : {"1;2", "abc", "1,", ",2", "1,2,3", "1,nan"}) {
    const CommandResult r = f.simulate(std::string("--eye-offset-mm ") + shell_quote(bad));
    expect_one_line_error(r, "--eye-offset-mm must be two numbers");
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_FALSE(std::filesystem::exists(f.retina)) << bad;
  }
}

TEST(SimulateCli, BadFocusAndPupil) {
  Fixture f;
  expect_one_line_error(f.simulate("--focus-mm -3"), "--focus-mm");
  expect_one_line_error(f.simulate("--focus-mm far"), "--focus-mm");
  expect_one_line_error(f.simulate("--pupil-mm 0"), "--pupil-mm");
  EXPECT_FALSE(std::filesystem::exists(f.retina));
}

TEST(SimulateCli, UnwritableOutput) {
  Fixture f;
  const auto missing_dir = f.dir / "no-such-dir" / "retina.png";
  CommandResult r = run_nelf("simulate " + q(f.still) + " --profile " + q(f.profile) + " -o " + q(missing_dir));
  expect_one_line_error(r, "cannot write --output");
  r = f.simulate("--ideal " + q(f.dir.path()));  // a directory
  expect_one_line_error(r, "cannot write --ideal");
  EXPECT_FALSE(std::filesystem::exists(f.retina));
  // An extension no image format claims: refused up front, nothing written.
  r = run_nelf("simulate " + q(f.still) + " --profile " + q(f.profile) + " -o " + q(f.dir / "retina.nosuchformat"));
  expect_one_line_error(r, "unknown image extension");
  int files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(f.dir.path())) ++files;
  EXPECT_EQ(files, 2);  // still.png and small.toml
}

// No output of simulate replaces its input (-o, --ideal, --sweep or the heatmap beside it): refused
// up front with status 2, the still byte for byte as it was. simulate always replaces its outputs, so
// `-o still.png` used to write the retinal image over the still.
TEST(SimulateCli, OutputOntoTheInputIsRefused) {
  Fixture f;
  const std::string bytes = read_file(f.still);
  const std::string still = q(f.still);
  const std::string head = "simulate " + still + " --profile " + q(f.profile);
  for (const std::string& args : {" -o " + still, " -o " + q(f.retina) + " --ideal " + still,
                                  " -o " + q(f.retina) + " --sweep " + q(f.dir / "still.csv")}) {
    SCOPED_TRACE(args);
    expect_clean_failure(f.dir, head + args, 2, "the output is the same file as the input");
    EXPECT_EQ(read_file(f.still), bytes);
  }
  // The gain heatmap beside the table (TABLE.gain.png) too.
  const auto named_like_the_gain = f.dir / "sweep.gain.png";
  std::filesystem::copy_file(f.still, named_like_the_gain);
  expect_clean_failure(f.dir,
                       "simulate " + q(named_like_the_gain) + " --profile " + q(f.profile) + " -o " + q(f.retina) +
                           " --depth estimate --sweep " + q(f.dir / "sweep.csv"),
                       2, "the output is the same file as the input");
  EXPECT_EQ(read_file(named_like_the_gain), bytes);
}

TEST(SimulateCli, StockProfileIsRejected) {
  Fixture f;
  const CommandResult r = run_nelf("simulate " + q(f.still) + " --profile hmz-t1-stock -o " + q(f.retina));
  expect_one_line_error(r, "lens_array");
  EXPECT_FALSE(std::filesystem::exists(f.retina));
}

}  // namespace
}  // namespace nelf::test
