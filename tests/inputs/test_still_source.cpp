#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <string>
#include <thread>

#include "inputs/still_source.hpp"
#include "support/image_files.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::filled_image;
using test::TempDir;
using test::write_test_image;

constexpr Rgba kReddish{0.8f, 0.2f, 0.1f, 1.f};
constexpr Rgba kBluish{0.1f, 0.2f, 0.8f, 1.f};

// A side-by-side frame: left half reddish, right half bluish, with a white marker at each half's
// top-left pixel block so orientation mistakes show.
Image sbs_frame(int w, int h) {
  Image frame(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) frame.at(x, y) = x < w / 2 ? kReddish : kBluish;
  return frame;
}

bool reddish(const Rgba& c) { return c.r > 0.6f && c.b < 0.3f; }
bool bluish(const Rgba& c) { return c.b > 0.6f && c.r < 0.3f; }

std::string still_error(const std::filesystem::path& path, const StillOptions& options = {}) {
  try {
    load_still(path, options);
  } catch (const StillError& e) {
    return e.what();
  }
  return "";
}

std::string read_error(const std::filesystem::path& path) {
  try {
    read_image_file(path);
  } catch (const StillError& e) {
    return e.what();
  }
  return "";
}

TEST(StillSource, ReadsGray8Bit) {
  TempDir dir;
  write_test_image(dir / "gray.png", filled_image(5, 3, {0.5f, 0.5f, 0.5f, 1.f}), 1);
  const Image image = read_image_file(dir / "gray.png");
  ASSERT_EQ(image.width(), 5);
  ASSERT_EQ(image.height(), 3);
  const Rgba c = image.at(4, 2);
  EXPECT_NEAR(c.r, 128.f / 255.f, 1e-6);
  EXPECT_EQ(c.r, c.g);
  EXPECT_EQ(c.r, c.b);
  EXPECT_EQ(c.a, 1.f);
}

TEST(StillSource, ReadsRgbAndRgba8Bit) {
  TempDir dir;
  Image rgb = filled_image(4, 2, {1.f, 0.f, 0.f, 1.f});
  rgb.at(3, 1) = {0.f, 0.f, 1.f, 1.f};
  write_test_image(dir / "rgb.png", rgb, 3);
  const Image a = read_image_file(dir / "rgb.png");
  EXPECT_EQ(a.at(0, 0).r, 1.f);
  EXPECT_EQ(a.at(0, 0).b, 0.f);
  EXPECT_EQ(a.at(3, 1).b, 1.f);
  EXPECT_EQ(a.at(3, 1).r, 0.f);
  EXPECT_EQ(a.at(3, 1).a, 1.f);

  write_test_image(dir / "rgba.png", filled_image(4, 2, {0.f, 1.f, 0.f, 1.f}), 4);
  const Image b = read_image_file(dir / "rgba.png");
  EXPECT_EQ(b.at(1, 1).g, 1.f);
  EXPECT_EQ(b.at(1, 1).a, 1.f);
}

TEST(StillSource, Reads16BitWithItsPrecision) {
  TempDir dir;
  const float value = 1000.f / 65535.f;  // not representable in 8 bits
  write_test_image(dir / "deep.png", filled_image(3, 3, {value, 0.f, 1.f, 1.f}), 3, OIIO::TypeDesc::UINT16);
  const Image image = read_image_file(dir / "deep.png");
  EXPECT_NEAR(image.at(1, 1).r, value, 1e-7);
  EXPECT_EQ(image.at(1, 1).b, 1.f);
}

TEST(StillSource, ReadsFloatTiff) {
  TempDir dir;
  write_test_image(dir / "f.tif", filled_image(3, 2, {0.123456f, 0.5f, 0.25f, 1.f}), 3, OIIO::TypeDesc::FLOAT);
  EXPECT_FLOAT_EQ(read_image_file(dir / "f.tif").at(2, 1).r, 0.123456f);
}

TEST(StillSource, BadFilesAreOneLineErrorsNamingTheFile) {
  TempDir dir;
  EXPECT_EQ(read_error(dir / "missing.png"), (dir / "missing.png").string() + ": no such file");

  test::write_file(dir / "garbage.png", std::string(4096, 'x'));
  std::string e = read_error(dir / "garbage.png");
  EXPECT_NE(e.find("garbage.png"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;

  write_test_image(dir / "whole.png", sbs_frame(64, 64), 3);
  const std::string png = test::read_file(dir / "whole.png");
  test::write_file(dir / "cut.png", png.substr(0, png.size() / 2));
  e = read_error(dir / "cut.png");
  EXPECT_NE(e.find("cut.png"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;

  test::write_file(dir / "huge.png", test::png_header_claiming(20000, 10));
  e = read_error(dir / "huge.png");
  EXPECT_NE(e.find("huge.png: 20000x10 is too large"), std::string::npos) << e;

  test::write_file(dir / "empty.png", test::png_header_claiming(0, 0));
  e = read_error(dir / "empty.png");
  EXPECT_NE(e.find("empty.png"), std::string::npos) << e;

  test::write_file(dir / "zero-bytes.png", "");
  EXPECT_NE(read_error(dir / "zero-bytes.png").find("zero-bytes.png"), std::string::npos);

  EXPECT_NE(read_error(dir.path()).find("not a regular file"), std::string::npos);
}

TEST(StillSource, RealImageOverTheLimitIsRefused) {
  TempDir dir;
  write_test_image(dir / "wide.png", filled_image(kMaxImageDimension + 1, 2, kReddish), 1);
  EXPECT_NE(read_error(dir / "wide.png").find("is too large"), std::string::npos);
}

TEST(StillSource, SideBySideByFilename) {
  TempDir dir;
  write_test_image(dir / "holiday.hsbs.png", sbs_frame(64, 18), 3);
  const StillStereo s = load_still(dir / "holiday.hsbs.png", {});
  EXPECT_EQ(s.decision.layout, StereoLayout::sbs_half);
  EXPECT_EQ(s.decision.rule, DetectionRule::filename);
  EXPECT_EQ(s.views.left.image.width(), 32);
  EXPECT_TRUE(reddish(s.views.left.image.at(31, 17)));
  EXPECT_TRUE(bluish(s.views.right.image.at(0, 0)));
  EXPECT_NEAR(s.views.left.aspect(), 64.0 / 18.0, 1e-12);

  const StillStereo swapped = load_still(dir / "holiday.hsbs.png", {std::nullopt, std::nullopt, true});
  EXPECT_TRUE(bluish(swapped.views.left.image.at(0, 0)));
  EXPECT_TRUE(reddish(swapped.views.right.image.at(0, 0)));
}

TEST(StillSource, ExplicitLayoutAndMono) {
  TempDir dir;
  write_test_image(dir / "plain.png", sbs_frame(40, 30), 3);
  const StillStereo mono = load_still(dir / "plain.png", {});
  EXPECT_EQ(mono.decision.layout, StereoLayout::mono);
  EXPECT_FALSE(mono.decision.warning.empty());
  EXPECT_EQ(mono.views.left.image.width(), 40);
  const StillStereo sbs = load_still(dir / "plain.png", {StereoLayout::sbs, std::nullopt, false});
  EXPECT_EQ(sbs.decision.rule, DetectionRule::flag);
  EXPECT_TRUE(sbs.decision.warning.empty());
  EXPECT_TRUE(reddish(sbs.views.left.image.at(0, 0)));
  EXPECT_TRUE(bluish(sbs.views.right.image.at(19, 29)));
}

TEST(StillSource, LayoutNotFittingNamesFileAndRule) {
  TempDir dir;
  write_test_image(dir / "odd.sbs.png", sbs_frame(41, 20), 3);
  const std::string e = still_error(dir / "odd.sbs.png");
  // A bare "sbs" on a frame of one view's aspect (2.05) is half width.
  EXPECT_NE(e.find("odd.sbs.png: layout sbs-half does not fit a 41x20 frame"), std::string::npos) << e;
  EXPECT_NE(e.find("filename rule"), std::string::npos) << e;
  write_test_image(dir / "odd.png", sbs_frame(41, 21), 3);
  const std::string f = still_error(dir / "odd.png", {StereoLayout::tab, std::nullopt, false});
  EXPECT_NE(f.find("even height"), std::string::npos) << f;
  EXPECT_EQ(f.find("rule"), std::string::npos) << f;
  write_test_image(dir / "notfp.png", sbs_frame(1280, 1440), 1);
  EXPECT_NE(still_error(dir / "notfp.png", {StereoLayout::fp, std::nullopt, false}).find("layout fp does not fit"),
            std::string::npos);
}

TEST(StillSource, Pair) {
  TempDir dir;
  write_test_image(dir / "l.png", filled_image(16, 9, kReddish), 3);
  write_test_image(dir / "r.png", filled_image(16, 9, kBluish), 3);
  write_test_image(dir / "r-small.png", filled_image(16, 8, kBluish), 3);
  const StillStereo s = load_still(dir / "l.png", {std::nullopt, dir / "r.png", false});
  EXPECT_EQ(s.decision.layout, StereoLayout::pair);
  EXPECT_TRUE(reddish(s.views.left.image.at(0, 0)));
  EXPECT_TRUE(bluish(s.views.right.image.at(0, 0)));
  EXPECT_NEAR(s.views.right.aspect(), 16.0 / 9.0, 1e-12);
  const StillStereo swapped = load_still(dir / "l.png", {StereoLayout::pair, dir / "r.png", true});
  EXPECT_TRUE(bluish(swapped.views.left.image.at(0, 0)));

  const std::string e = still_error(dir / "l.png", {std::nullopt, dir / "r-small.png", false});
  EXPECT_NE(e.find("is 16x9 but"), std::string::npos) << e;
  EXPECT_NE(e.find("r-small.png is 16x8"), std::string::npos) << e;
  EXPECT_NE(still_error(dir / "l.png", {StereoLayout::pair, std::nullopt, false}).find("--right"), std::string::npos);
  EXPECT_NE(still_error(dir / "l.png", {StereoLayout::sbs, dir / "r.png", false}).find("does not apply"),
            std::string::npos);
}

TEST(StillSource, JpsIsRightLeft) {
  TempDir dir;
  // Written as JPEG; the .jps name is what makes it JPS.
  write_test_image(dir / "photo.jps", sbs_frame(64, 24), 3, OIIO::TypeDesc::UINT8, "jpeg");
  const StillStereo s = load_still(dir / "photo.jps", {});
  EXPECT_EQ(s.decision.layout, StereoLayout::sbs);
  EXPECT_EQ(s.views.left.image.width(), 32);
  // The left half of a JPS is the right eye's view.
  EXPECT_TRUE(bluish(s.views.left.image.at(16, 12)));
  EXPECT_TRUE(reddish(s.views.right.image.at(16, 12)));
  // --swap-eyes on a JPS undoes the convention (a mislabelled left-right file).
  const StillStereo undone = load_still(dir / "photo.jps", {std::nullopt, std::nullopt, true});
  EXPECT_TRUE(reddish(undone.views.left.image.at(16, 12)));
}

std::string jpeg_bytes(const TempDir& dir, const Image& image, const std::string& name) {
  write_test_image(dir / name, image, 3, OIIO::TypeDesc::UINT8, "jpeg");
  return test::read_file(dir / name);
}

TEST(StillSource, MpoIsLeftThenRight) {
  TempDir dir;
  const std::string left = jpeg_bytes(dir, filled_image(48, 32, kReddish), "l.jpg");
  const std::string right = jpeg_bytes(dir, filled_image(48, 32, kBluish), "r.jpg");
  test::write_file(dir / "pair.mpo", left + right);
  const StillStereo s = load_still(dir / "pair.mpo", {});
  EXPECT_EQ(s.decision.layout, StereoLayout::pair);
  ASSERT_EQ(s.views.left.image.width(), 48);
  EXPECT_TRUE(reddish(s.views.left.image.at(10, 10)));
  EXPECT_TRUE(bluish(s.views.right.image.at(10, 10)));
  EXPECT_NEAR(s.views.left.aspect(), 1.5, 1e-12);
}

TEST(StillSource, MpoWithEmbeddedThumbnail) {
  TempDir dir;
  // Cameras put an EXIF thumbnail (a whole JPEG) inside the first image's APP1 segment.
  const std::string thumbnail = jpeg_bytes(dir, filled_image(8, 8, {0, 1, 0, 1}), "t.jpg");
  const std::string left =
      test::with_embedded_thumbnail(jpeg_bytes(dir, filled_image(48, 32, kReddish), "l.jpg"), thumbnail);
  const std::string right = jpeg_bytes(dir, filled_image(48, 32, kBluish), "r.jpg");
  test::write_file(dir / "camera.MPO", left + std::string(16, '\0') + right);
  const auto bytes = test::read_file(dir / "camera.MPO");
  const auto starts = find_jpeg_images(std::as_bytes(std::span(bytes.data(), bytes.size())));
  ASSERT_EQ(starts.size(), 2u);
  EXPECT_EQ(starts[0], 0u);
  EXPECT_EQ(starts[1], left.size() + 16);
  const StillStereo s = load_still(dir / "camera.MPO", {});
  EXPECT_EQ(s.views.left.image.width(), 48);
  EXPECT_TRUE(reddish(s.views.left.image.at(0, 0)));
  EXPECT_TRUE(bluish(s.views.right.image.at(0, 0)));
}

TEST(StillSource, MpoIndexBeatsScanning) {
  TempDir dir;
  const std::string left = jpeg_bytes(dir, filled_image(48, 32, kReddish), "l.jpg");
  const std::string right = jpeg_bytes(dir, filled_image(48, 32, kBluish), "r.jpg");
  // Bytes between the images that look like an SOI: a scanner takes them for the second image.
  const std::string decoy = std::string("\xFF\xD8\xFF\xE0", 4) + std::string(60, '\x11');
  const std::string mpo = test::mpo_with_index(left, decoy, right);
  const auto bytes = std::as_bytes(std::span(mpo.data(), mpo.size()));
  const std::size_t right_start = mpo.size() - right.size();
  ASSERT_EQ(find_jpeg_images(bytes).size(), 2u);
  EXPECT_NE(find_jpeg_images(bytes)[1], right_start);  // fooled by the decoy
  EXPECT_EQ(find_mpo_images(bytes), (std::vector<std::size_t>{0, right_start}));
  test::write_file(dir / "indexed.mpo", mpo);
  const StillStereo s = load_still(dir / "indexed.mpo", {});
  EXPECT_TRUE(reddish(s.views.left.image.at(0, 0)));
  EXPECT_TRUE(bluish(s.views.right.image.at(47, 31)));

  // An index pointing at something that is not a JPEG is ignored in favour of scanning.
  std::string broken = test::mpo_with_index(left, "", right);
  const auto broken_bytes = std::as_bytes(std::span(broken.data(), broken.size()));
  EXPECT_EQ(find_mpo_images(broken_bytes)[1], broken.size() - right.size());
  broken[broken.size() - right.size() + 1] = 'x';  // destroy the right image's SOI
  EXPECT_EQ(find_mpo_images(broken_bytes), find_jpeg_images(broken_bytes));
}

// An MP index whose right-image entry points back at the first image: taking it would decode an empty
// left view ("cannot decode" for a good file); it is ignored in favour of scanning, as a broken
// index is. Found by tests/fuzz/fuzz_still.
TEST(StillSource, MpoIndexListingOneImageTwiceIsIgnored) {
  TempDir dir;
  const std::string left = jpeg_bytes(dir, filled_image(48, 32, kReddish), "l.jpg");
  const std::string right = jpeg_bytes(dir, filled_image(48, 32, kBluish), "r.jpg");
  std::string mpo = test::mpo_with_index(left, "", right);
  // The right image's MP entry: attribute 0x00020002, size, then the offset, which becomes 0 (= the
  // start of the file, where the left image is).
  const std::size_t entry = mpo.find(test::le32(0x00020002) + test::le32(static_cast<std::uint32_t>(right.size())));
  ASSERT_NE(entry, std::string::npos);
  mpo.replace(entry + 8, 4, test::le32(0));
  const auto bytes = std::as_bytes(std::span(mpo.data(), mpo.size()));
  const std::size_t right_start = mpo.size() - right.size();
  EXPECT_EQ(find_mpo_images(bytes), (std::vector<std::size_t>{0, right_start}));
  test::write_file(dir / "twice.mpo", mpo);
  const StillStereo s = load_still(dir / "twice.mpo", {});
  EXPECT_TRUE(reddish(s.views.left.image.at(0, 0)));
  EXPECT_TRUE(bluish(s.views.right.image.at(0, 0)));
}

TEST(StillSource, BadMpo) {
  TempDir dir;
  const std::string left = jpeg_bytes(dir, filled_image(48, 32, kReddish), "l.jpg");
  test::write_file(dir / "single.mpo", left);
  EXPECT_NE(still_error(dir / "single.mpo").find("single.mpo: the MPO file holds 1 image(s)"), std::string::npos);
  const std::string right = jpeg_bytes(dir, filled_image(40, 32, kBluish), "r.jpg");
  test::write_file(dir / "sizes.mpo", left + right);
  EXPECT_NE(still_error(dir / "sizes.mpo").find("48x32 but its right image is 40x32"), std::string::npos);
  test::write_file(dir / "cut.mpo", left + right.substr(0, right.size() / 3));
  const std::string e = still_error(dir / "cut.mpo");
  EXPECT_NE(e.find("cut.mpo"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  test::write_file(dir / "pair.mpo", left + jpeg_bytes(dir, filled_image(48, 32, kBluish), "r2.jpg"));
  EXPECT_NE(still_error(dir / "pair.mpo", {StereoLayout::sbs, std::nullopt, false}).find("does not apply"),
            std::string::npos);
}

TEST(StillSource, PixelLimitIsCheckedForEveryFormatAndView) {
  TempDir dir;
  write_test_image(dir / "photo.jpg", filled_image(300, 200, kReddish), 3, OIIO::TypeDesc::UINT8, "jpeg");
  write_test_image(dir / "photo.tif", filled_image(300, 200, kReddish), 3);
  write_test_image(dir / "photo.png", filled_image(300, 200, kReddish), 3);
  for (const char* name : {"photo.jpg", "photo.tif", "photo.png"}) {
    SCOPED_TRACE(name);
    try {
      read_image_file(dir / name, 59999);
      ADD_FAILURE() << "read over the limit";
    } catch (const StillError& e) {
      EXPECT_EQ(std::string(e.what()), (dir / name).string() +
                                           ": 300x200 is 60000 pixels, more than the limit of 59999 (--max-pixels "
                                           "raises it)");
    }
    EXPECT_EQ(read_image_file(dir / name, 60000).width(), 300);
  }
  // Each view of an MPO is one image of the limit.
  const std::string left = jpeg_bytes(dir, filled_image(300, 200, kReddish), "l.jpg");
  const std::string right = jpeg_bytes(dir, filled_image(300, 200, kBluish), "r.jpg");
  test::write_file(dir / "pair.mpo", left + right);
  StillOptions options;
  options.max_pixels = 59999;
  EXPECT_NE(still_error(dir / "pair.mpo", options).find("pair.mpo (left image): 300x200 is 60000 pixels"),
            std::string::npos)
      << still_error(dir / "pair.mpo", options);
  options.max_pixels = 60000;
  EXPECT_EQ(still_error(dir / "pair.mpo", options), "");
}

// A damaged PNG is reported in its error's text only: nothing is printed (libpng's default handler
// would), and stderr is not muted meanwhile either, which would swallow what other threads print.
TEST(StillSource, DamagedPngPrintsNothingAndMutesNothing) {
  TempDir dir;
  Image noise(1500, 1500);  // big enough to take a while to decode
  unsigned state = 1;
  for (Rgba& px : noise.pixels()) {
    state = state * 1103515245u + 12345u;
    px = {static_cast<float>(state >> 24) / 255.f, static_cast<float>((state >> 16) & 255) / 255.f, 0.2f, 1.f};
  }
  write_test_image(dir / "whole.png", noise, 3);
  std::string png = test::read_file(dir / "whole.png");
  for (std::size_t i = png.size() - 2000; i < png.size() - 1000; ++i) png[i] = static_cast<char>(~png[i]);
  test::write_file(dir / "damaged.png", png);

  // fd 2 into a file for the duration; a second thread prints numbered lines all along.
  std::fflush(stderr);
  const int saved = ::dup(STDERR_FILENO);
  ASSERT_GE(saved, 0);
  const auto captured = dir / "stderr.txt";
  std::FILE* sink = std::fopen(captured.c_str(), "w");
  ASSERT_NE(sink, nullptr);
  ::dup2(::fileno(sink), STDERR_FILENO);
  std::atomic<bool> done{false};
  int printed = 0;
  std::thread other([&] {
    while (!done) {
      const std::string line = "tick " + std::to_string(printed++) + "\n";
      [[maybe_unused]] const auto written = ::write(STDERR_FILENO, line.data(), line.size());
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  });
  std::string error;
  for (int i = 0; i < 5; ++i) error = read_error(dir / "damaged.png");
  done = true;
  other.join();
  ::dup2(saved, STDERR_FILENO);
  ::close(saved);
  std::fclose(sink);

  EXPECT_NE(error.find("damaged.png: cannot read the image: "), std::string::npos) << error;
  const std::string out = test::read_file(captured);
  EXPECT_EQ(out.find("libpng"), std::string::npos) << out;
  std::string expected;
  for (int i = 0; i < printed; ++i) expected += "tick " + std::to_string(i) + "\n";
  EXPECT_EQ(out, expected) << "lines printed by another thread were lost";
}

}  // namespace
}  // namespace nelf
