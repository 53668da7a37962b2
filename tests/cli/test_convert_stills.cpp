// `nelf convert` on still images, run as a user would: output geometry per signal, and every bad
// input ending in one clear line, a non-zero status and no file (not even a temporary one) left.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "support/image_files.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::expect_clean_failure;
using test::files_in;
using test::filled_image;
using test::q;
using test::read_back;
using test::run_nelf;
using test::TempDir;
using test::write_test_image;

// A stereo view with structure (stripes) so that the elemental images are not flat: the left one
// reddish, the right one bluish.
Image view_image(int w, int h, bool left) {
  Image image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float stripe = (x / 8) % 2 ? 1.f : 0.6f;
      image.at(x, y) = left ? Rgba{stripe, 0.1f, 0.1f, 1.f} : Rgba{0.1f, 0.1f, stripe, 1.f};
    }
  return image;
}

// Full side-by-side frame of two w x h views.
Image sbs_image(int w, int h) {
  const Image l = view_image(w, h, true), r = view_image(w, h, false);
  Image frame(2 * w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      frame.at(x, y) = l.at(x, y);
      frame.at(w + x, y) = r.at(x, y);
    }
  return frame;
}

struct AreaStats {
  double red = 0, green = 0, blue = 0;
  long non_black = 0;
};
AreaStats stats(const test::ReadBack& img, int x0, int y0, int x1, int y1) {
  AreaStats s;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const float r = img.at(x, y, 0), g = img.at(x, y, 1), b = img.at(x, y, 2);
      s.red += r, s.green += g, s.blue += b;
      s.non_black += (r + g + b) > 0.f;
    }
  return s;
}

std::filesystem::path small_profile(const TempDir& dir) { return test::write_small_profile(dir); }

TEST(ConvertStills, HmzT1FramePackedPng) {
  TempDir dir;
  write_test_image(dir / "sbs.png", sbs_image(640, 360), 3);
  const auto start = std::chrono::steady_clock::now();
  const auto r = run_nelf("convert " + q(dir / "sbs.png") + " " + q(dir / "out.png") + " --profile hmz-t1");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RecordProperty("seconds", std::to_string(seconds));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const auto out = read_back(dir / "out.png");
  ASSERT_EQ(out.width, 1280);
  ASSERT_EQ(out.height, 1470);
  const AreaStats left = stats(out, 0, 0, 1280, 720), gap = stats(out, 0, 720, 1280, 750),
                  right = stats(out, 0, 750, 1280, 1470);
  EXPECT_EQ(gap.non_black, 0);
  EXPECT_GT(left.non_black, 1280 * 720 / 4);
  EXPECT_GT(right.non_black, 1280 * 720 / 4);
  // The left eye shows the left (reddish) view, the right eye the right (bluish) one.
  EXPECT_GT(left.red, 3 * left.blue);
  EXPECT_GT(right.blue, 3 * right.red);
  EXPECT_EQ(files_in(dir.path()), (std::vector<std::string>{"out.png", "sbs.png"}));
}

TEST(ConvertStills, SignalsGiveTheirFrameSizes) {
  TempDir dir;
  const auto profile = small_profile(dir);
  write_test_image(dir / "in.png", sbs_image(320, 180), 3);
  struct Case {
    const char* signal;
    int w, h;
  };
  for (const Case& c :
       {Case{"sbs", 320, 90}, Case{"tab", 160, 180}, Case{"left", 160, 90}, Case{"right", 160, 90},
        Case{"hdmi-fp-720p60", 1280, 1470}, Case{"hdmi-fp-720p50", 1280, 1470}, Case{"hdmi-fp-1080p24", 1920, 2205}}) {
    SCOPED_TRACE(c.signal);
    const auto out = dir / (std::string(c.signal) + ".png");
    const auto r = run_nelf("convert " + q(dir / "in.png") + " " + q(out) + " --layout sbs --profile " + q(profile) +
                            " --signal " + c.signal);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto img = read_back(out);
    EXPECT_EQ(img.width, c.w);
    EXPECT_EQ(img.height, c.h);
  }
  const auto left = read_back(dir / "left.png"), right = read_back(dir / "right.png");
  const AreaStats l = stats(left, 0, 0, 160, 90), rr = stats(right, 0, 0, 160, 90);
  EXPECT_GT(l.red, 3 * l.blue);
  EXPECT_GT(rr.blue, 3 * rr.red);
  // A 160x90 panel on an HDMI signal is centred 1:1 with black around it.
  const auto fp = read_back(dir / "hdmi-fp-720p60.png");
  EXPECT_EQ(stats(fp, 0, 0, 1280, 315).non_black, 0);
  EXPECT_EQ(stats(fp, 0, 0, 560, 720).non_black, 0);
  EXPECT_GT(stats(fp, 560, 315, 720, 405).non_black, 0);
  EXPECT_GT(stats(fp, 560, 750 + 315, 720, 750 + 405).non_black, 0);
}

TEST(ConvertStills, SixteenBitAndOverwrite) {
  TempDir dir;
  const auto profile = small_profile(dir);
  write_test_image(dir / "in.png", sbs_image(320, 180), 3);
  const std::string base =
      "convert " + q(dir / "in.png") + " " + q(dir / "out.png") + " --layout sbs --profile " + q(profile);
  ASSERT_EQ(run_nelf(base + " --signal sbs --bits 16").status, 0);
  EXPECT_EQ(read_back(dir / "out.png").width, 320);
  EXPECT_EQ(read_back(dir / "out.png").bits, 16);
  auto r = run_nelf(base + " --signal sbs");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "nelf: " + (dir / "out.png").string() + " exists; pass -y to overwrite\n");
  r = run_nelf(base + " --signal tab -y");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_back(dir / "out.png").height, 180);
  EXPECT_EQ(read_back(dir / "out.png").bits, 8);
  EXPECT_EQ(files_in(dir.path()), (std::vector<std::string>{"in.png", "out.png", "small.toml"}));
}

TEST(ConvertStills, MonoFallbackWarns) {
  TempDir dir;
  const auto profile = small_profile(dir);
  write_test_image(dir / "holiday.png", view_image(160, 120, true), 3);
  const auto r = run_nelf("convert " + q(dir / "holiday.png") + " " + q(dir / "out.png") + " --signal sbs --profile " +
                          q(profile));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: warning: no stereo layout detected for holiday.png"), std::string::npos) << r.err;
  const auto out = read_back(dir / "out.png");
  EXPECT_GT(stats(out, 160, 0, 320, 90).red, 3 * stats(out, 160, 0, 320, 90).blue);  // both eyes see the one view
}

// Every still format routes the left view to the left eye: the sbs output's left half is reddish.
TEST(ConvertStills, EveryStillFormatRoutesTheEyes) {
  TempDir dir;
  const auto profile = small_profile(dir);
  const Image l = view_image(320, 180, true), r = view_image(320, 180, false);
  write_test_image(dir / "l.png", l, 3);
  write_test_image(dir / "r.png", r, 3);
  write_test_image(dir / "rl.png", sbs_image(320, 180), 3);  // left-right; --swap-eyes makes it right-left
  Image tab(320, 360), fp(1280, 1470), jps(640, 180);
  for (int y = 0; y < 180; ++y)
    for (int x = 0; x < 320; ++x) {
      tab.at(x, y) = l.at(x, y);
      tab.at(x, 180 + y) = r.at(x, y);
      jps.at(x, y) = r.at(x, y);  // JPS: right view first
      jps.at(320 + x, y) = l.at(x, y);
    }
  for (int y = 0; y < 720; ++y)
    for (int x = 0; x < 1280; ++x) {
      fp.at(x, y) = l.at(x % 320, y % 180);
      fp.at(x, 750 + y) = r.at(x % 320, y % 180);
    }
  write_test_image(dir / "movie.Half-OU.png", tab, 3);
  write_test_image(dir / "packed.png", fp, 3);
  write_test_image(dir / "photo.jps", jps, 3, OIIO::TypeDesc::UINT8, "jpeg");
  write_test_image(dir / "l.jpg", l, 3, OIIO::TypeDesc::UINT8, "jpeg");
  write_test_image(dir / "r.jpg", r, 3, OIIO::TypeDesc::UINT8, "jpeg");
  test::write_file(dir / "camera.mpo", test::read_file(dir / "l.jpg") + test::read_file(dir / "r.jpg"));

  const std::string inputs[] = {
      q(dir / "l.png") + " --right " + q(dir / "r.png"),
      q(dir / "movie.Half-OU.png"),
      q(dir / "packed.png"),
      q(dir / "photo.jps"),
      q(dir / "camera.mpo"),
      q(dir / "r.png") + " --right " + q(dir / "l.png") + " --swap-eyes",
  };
  int n = 0;
  for (const auto& input : inputs) {
    SCOPED_TRACE(input);
    const auto out = dir / ("out" + std::to_string(n++) + ".png");
    const auto result = run_nelf("convert " + input + " " + q(out) + " --signal sbs --profile " + q(profile));
    ASSERT_EQ(result.status, 0) << result.err;
    EXPECT_EQ(result.err, "");
    const auto img = read_back(out);
    ASSERT_EQ(img.width, 320);
    const AreaStats left = stats(img, 0, 0, 160, 90), right = stats(img, 160, 0, 320, 90);
    EXPECT_GT(left.red, 3 * left.blue);
    EXPECT_GT(right.blue, 3 * right.red);
  }
  // A left-right frame with --swap-eyes puts the right (bluish) half in the left eye.
  const auto swapped = dir / "swapped.png";
  ASSERT_EQ(run_nelf("convert " + q(dir / "rl.png") + " " + q(swapped) +
                     " --layout sbs --swap-eyes --signal sbs "
                     "--profile " +
                     q(profile))
                .status,
            0);
  const auto img = read_back(swapped);
  EXPECT_GT(stats(img, 0, 0, 160, 90).blue, 3 * stats(img, 0, 0, 160, 90).red);
}

TEST(ConvertStills, BadInputFiles) {
  TempDir dir;
  const auto profile = small_profile(dir);
  const std::string tail = " " + q(dir / "out.png") + " --profile " + q(profile);
  write_test_image(dir / "whole.png", sbs_image(320, 180), 3);
  const std::string png = test::read_file(dir / "whole.png");
  test::write_file(dir / "cut.png", png.substr(0, png.size() / 2));
  test::write_file(dir / "garbage.png", std::string(5000, '\x5a'));
  test::write_file(dir / "huge.png", test::png_header_claiming(20000, 10));
  test::write_file(dir / "zero.png", test::png_header_claiming(0, 0));
  write_test_image(dir / "odd.png", view_image(321, 180, true), 3);
  write_test_image(dir / "right-small.png", view_image(320, 170, false), 3);
  write_test_image(dir / "p720.png", view_image(1280, 720, true), 3);
  write_test_image(dir / "left.jpg", view_image(64, 32, true), 3, OIIO::TypeDesc::UINT8, "jpeg");
  test::write_file(dir / "one.mpo", test::read_file(dir / "left.jpg"));

  expect_clean_failure(dir, "convert " + q(dir / "missing.png") + tail, 1, "missing.png: no such file");
  expect_clean_failure(dir, "convert " + q(dir / "cut.png") + tail, 1, "cut.png: cannot read the image");
  expect_clean_failure(dir, "convert " + q(dir / "garbage.png") + tail, 1, "garbage.png");
  expect_clean_failure(dir, "convert " + q(dir / "huge.png") + tail, 1, "huge.png: 20000x10 is too large");
  expect_clean_failure(dir, "convert " + q(dir / "zero.png") + tail, 1, "zero.png");
  expect_clean_failure(dir, "convert " + q(dir / "odd.png") + tail + " --layout sbs", 1,
                       "odd.png: layout sbs does not fit a 321x180 frame: side-by-side needs an even width");
  expect_clean_failure(dir, "convert " + q(dir / "whole.png") + tail + " --right " + q(dir / "right-small.png"), 1,
                       "is 640x180 but");
  expect_clean_failure(dir, "convert " + q(dir / "p720.png") + tail + " --layout fp", 1,
                       "p720.png: layout fp does not fit a 1280x720 frame");
  expect_clean_failure(dir, "convert " + q(dir / "one.mpo") + tail, 1, "one.mpo: the MPO file holds 1 image(s)");
}

TEST(ConvertStills, BadOutputs) {
  TempDir dir;
  const auto profile = small_profile(dir);
  write_test_image(dir / "in.png", sbs_image(320, 180), 3);
  test::write_file(dir / "taken.png", "precious");
  test::write_file(dir / "a-file", "");
  const std::string head = "convert " + q(dir / "in.png") + " ";
  const std::string tail = " --layout sbs --profile " + q(profile);
  expect_clean_failure(dir, head + q(dir / "no-such-dir" / "out.png") + tail, 1, "no-such-dir does not exist");
  expect_clean_failure(dir, head + q(dir / "a-file" / "out.png") + tail, 1, "does not exist");
  expect_clean_failure(dir, head + q(dir / "taken.png") + tail, 1, "taken.png exists; pass -y to overwrite");
  EXPECT_EQ(test::read_file(dir / "taken.png"), "precious");
  expect_clean_failure(dir, head + q(dir / "out.gif") + tail, 1, "unknown image extension '.gif'");
  expect_clean_failure(dir, head + q(dir / "out.jpg") + tail + " --bits 16", 1, "16-bit output needs .png or .tif");
  if (::geteuid() != 0) {  // root writes anywhere
    std::filesystem::create_directory(dir / "locked");
    std::filesystem::permissions(dir / "locked",
                                 std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    expect_clean_failure(dir, head + q(dir / "locked" / "out.png") + tail, 1, "is not writable");
  }
}

// An output that is one of the inputs is refused before any work, -y or not: one line, status 2,
// the input byte for byte as it was (by name, another spelling, a symlink or hard link, the --right
// view). A dangling symlink at the output name needs -y like any existing name.
TEST(ConvertStills, OutputOntoAnInputIsRefused) {
  TempDir dir;
  const auto profile = small_profile(dir);
  write_test_image(dir / "in.png", sbs_image(320, 180), 3);
  write_test_image(dir / "left.png", view_image(160, 180, true), 3);
  write_test_image(dir / "right.png", view_image(160, 180, false), 3);
  std::filesystem::create_symlink(dir / "in.png", dir / "link.png");
  std::filesystem::create_hard_link(dir / "in.png", dir / "hard.png");
  std::filesystem::create_symlink(dir / "missing.png", dir / "dangling.png");
  const std::string in_bytes = test::read_file(dir / "in.png"), right_bytes = test::read_file(dir / "right.png");
  const std::string in = "convert " + q(dir / "in.png") + " ";
  const std::string tail = " --layout sbs --profile " + q(profile);
  const std::string same = "the output is the same file as the input";
  for (const std::string overwrite : {"", " -y"}) {
    SCOPED_TRACE(overwrite);
    expect_clean_failure(dir, in + q(dir / "in.png") + tail + overwrite, 2, same);
    expect_clean_failure(dir, in + q(dir.path().string() + "/./in.png") + tail + overwrite, 2, same);
    expect_clean_failure(dir, in + q(dir / "link.png") + tail + overwrite, 2, same);
    expect_clean_failure(dir, in + q(dir / "hard.png") + tail + overwrite, 2, same);
    expect_clean_failure(dir,
                         "convert " + q(dir / "left.png") + " --right " + q(dir / "right.png") + " " +
                             q(dir / "right.png") + " --profile " + q(profile) + overwrite,
                         2, "the same file as the --right view");
    EXPECT_EQ(test::read_file(dir / "in.png"), in_bytes);
    EXPECT_EQ(test::read_file(dir / "right.png"), right_bytes);
    EXPECT_TRUE(std::filesystem::is_symlink(dir / "link.png"));
  }
  expect_clean_failure(dir, in + q(dir / "dangling.png") + tail, 1, "dangling.png exists; pass -y to overwrite");
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "dangling.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "missing.png"));
}

TEST(ConvertStills, BadArgumentsExitTwoBeforeAnyWork) {
  TempDir dir;
  write_test_image(dir / "in.png", sbs_image(32, 18), 3);
  const std::string head = "convert " + q(dir / "in.png") + " " + q(dir / "out.png");
  expect_clean_failure(dir, head + " --layout side-by-side", 2, "unknown layout 'side-by-side' (use auto, sbs,");
  expect_clean_failure(dir, head + " --layout alt", 2, "needs a video");
  expect_clean_failure(dir, head + " --layout pair", 2, "--right FILE");
  expect_clean_failure(dir, head + " --layout sbs --right " + q(dir / "in.png"), 2, "layout sbs does not apply");
  expect_clean_failure(dir, head + " --signal hdmi-fp-1080p60", 2, "unknown signal 'hdmi-fp-1080p60'");
  expect_clean_failure(dir, head + " --fsaa 3", 2, "--fsaa must be 0, 1, 4 or 16, got 3");
  expect_clean_failure(dir, head + " --profile no-such-profile", 2, "no-such-profile");
  expect_clean_failure(dir, "convert " + q(dir / "in.png"), 2, "output");
  // Arguments are checked before the input is read: a missing input with a bad signal is a status 2.
  expect_clean_failure(dir, "convert " + q(dir / "missing.png") + " " + q(dir / "out.png") + " --signal x", 2,
                       "unknown signal");
}

// Found by fuzzing (docs/fuzzing.md, finding 6): 22 bytes of a raw WebP lossless (VP8L) stream whose
// header claims 16384 x 8192 pixels, under the default --max-pixels. The whole float image was
// allocated (2 GB) before the decoder failed; now the rows are read in bands, so the memory is the
// decoder's own. Under a 1.6 GB address-space limit it used to end in bad_alloc; now it fails with
// the decoder's one line.
TEST(ConvertStills, ATinyFileClaimingThePixelLimitFailsWithoutThatMemory) {
  TempDir dir;
  const unsigned char vp8l[] = {0x2f, 0xff, 0xff, 0xff, 0x17, 0x00, 0x40, 0xec, 0x00, 0xff, 0xda,
                                0xff, 0xd9, 0x2e, 0x3a, 0xd9, 0xb9, 0x10, 0x4e, 0x2e, 0x47, 0xe2};
  test::write_file(dir / "claims.png", std::string(reinterpret_cast<const char*>(vp8l), sizeof vp8l));
  const auto r = test::run_command("ulimit -v 1600000; " + std::string(NELF_BINARY) + " convert " +
                                   q(dir / "claims.png") + " " + q(dir / "out.png"));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err.find("bad_alloc"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("claims.png: cannot read the image"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.png"));
}

}  // namespace
}  // namespace nelf
