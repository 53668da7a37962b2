// Every error is one line on stderr (DESIGN.md §11), also when the text in it comes from outside:
// a file name or a shared profile can hold newlines and terminal escape sequences, and a library
// (libpng) can have its own say. Run as a user would.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "support/image_files.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::expect_clean_failure;
using test::q;
using test::run_nelf;
using test::TempDir;

// Bytes a terminal would act on: C0 controls (the final newline aside), DEL, C1 controls in UTF-8.
bool has_raw_controls(const std::string& err) {
  const std::string body = err.empty() || err.back() != '\n' ? err : err.substr(0, err.size() - 1);
  for (std::size_t i = 0; i < body.size(); ++i) {
    const auto c = static_cast<unsigned char>(body[i]);
    if (c < 0x20 || c == 0x7F) return true;
    if (c == 0xC2 && i + 1 < body.size() && static_cast<unsigned char>(body[i + 1]) <= 0x9F) return true;
  }
  return false;
}

void expect_one_clean_line(const test::CommandResult& r, int status, const std::string& expected) {
  EXPECT_EQ(r.status, status) << r.err;
  EXPECT_EQ(r.err.rfind("nelf: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(has_raw_controls(r.err)) << r.err;
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
}

TEST(OneLineErrors, ProfileTextIsEscaped) {
  TempDir dir;
  test::write_test_image(dir / "in.png", test::filled_image(64, 32, {1, 0, 0, 1}), 3);
  const std::string run = "convert " + q(dir / "in.png") + " " + q(dir / "out.png") + " --profile ";
  std::string profile = test::read_file(test::write_small_profile(dir));

  // A value with a newline, an ANSI colour and an OSC title sequence (as a shared profile could
  // carry to retitle or recolour the user's terminal).
  test::write_file(dir / "value.toml",
                   profile + "\n[output]\nsignal = \"red\\u001b[31m\\nline\\u001b]0;pwned\\u0007\"\n");
  expect_one_clean_line(run_nelf(run + q(dir / "value.toml")), 2, "got \"red\\x1b[31m\\nline\\x1b]0;pwned\\x07\"");

  // A key: quoted TOML keys may hold any character.
  test::write_file(dir / "key.toml", profile + "\n\"\\u001b[2Jwipe\\nkey\" = 1\n");
  expect_one_clean_line(run_nelf(run + q(dir / "key.toml")), 2, "\\x1b[2Jwipe\\nkey is not a known key");

  // A C1 control (U+009B, a one-character CSI) and invalid UTF-8 are shown escaped too.
  test::write_file(dir / "c1.toml", profile + "\n\"\\u009b31mkey\" = 1\n");
  expect_one_clean_line(run_nelf(run + q(dir / "c1.toml")), 2, "\\u009b31mkey");

  // An array written over several lines is shown on one.
  std::string lines = profile;
  const auto at = lines.find("resolution = [");
  lines.replace(at, lines.find(']', at) - at + 1, "resolution = [\n  160,\n  90,\n  3,\n]");
  test::write_file(dir / "lines.toml", lines);
  expect_one_clean_line(run_nelf(run + q(dir / "lines.toml")), 2, "got [160, 90, 3]");
}

TEST(OneLineErrors, FileNamesAreEscaped) {
  TempDir dir;
  const auto profile = test::write_small_profile(dir);
  const auto name = dir / "two\nlines\x1b[31m.png";
  test::write_file(name, std::string(5000, '\x5a'));  // not an image
  expect_one_clean_line(run_nelf("convert " + q(name) + " " + q(dir / "out.png") + " --profile " + q(profile)), 1,
                        "two\\nlines\\x1b[31m.png");
  const auto missing = dir / "gone\n.mkv";
  expect_one_clean_line(run_nelf("probe " + q(missing)), 1, "gone\\n.mkv: no such file");
  // Printable UTF-8 is kept as it is.
  expect_one_clean_line(run_nelf("probe " + q(dir / "Amélie 3D 映画.mkv")), 1, "Amélie 3D 映画.mkv: no such file");
}

TEST(OneLineErrors, DamagedPngIsOneLineWithLibpngsReason) {
  TempDir dir;
  const auto profile = test::write_small_profile(dir);
  Image noise(320, 180);
  unsigned state = 1;
  for (Rgba& px : noise.pixels()) {
    state = state * 1103515245u + 12345u;
    px = {static_cast<float>(state >> 24) / 255.f, 0.5f, 0.2f, 1.f};
  }
  test::write_test_image(dir / "whole.png", noise, 3);
  std::string png = test::read_file(dir / "whole.png");
  std::filesystem::remove(dir / "whole.png");
  const std::size_t idat = png.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  std::string flipped = png;
  for (std::size_t i = idat + 40; i < idat + 60; ++i) flipped[i] = static_cast<char>(~flipped[i]);
  test::write_file(dir / "flipped.png", flipped);
  test::write_file(dir / "cut.png", png.substr(0, png.size() / 2));
  const std::string tail = " " + q(dir / "out.png") + " --profile " + q(profile);
  // libpng's own line ("libpng error: ...") used to come first; now its reason is in nelf's line.
  expect_clean_failure(dir, "convert " + q(dir / "flipped.png") + tail, 1, "flipped.png: cannot read the image: ");
  expect_clean_failure(dir, "convert " + q(dir / "cut.png") + tail, 1, "cut.png: cannot read the image: ");
  const auto r = run_nelf("convert " + q(dir / "flipped.png") + tail);
  EXPECT_EQ(r.err.find("libpng"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace nelf
