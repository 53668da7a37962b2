// Decompression bombs (DESIGN.md §11): images and video frames over --max-pixels are refused from
// their headers, before anything is decoded, quickly and in one line; a larger limit lets them in.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "support/image_files.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::expect_clean_failure;
using test::make_media;
using test::q;
using test::TempDir;

// A flat grey 8-bit PNG of `width` x `height`, written row by row: a decompression bomb (16384x16384
// is 268 Mpx in about a megabyte) made in seconds and a few KB of memory.
void write_flat_png(const std::filesystem::path& path, int width, int height) {
  auto out = OIIO::ImageOutput::create("png");
  if (!out) throw std::runtime_error("no OIIO PNG writer: " + OIIO::geterror());
  OIIO::ImageSpec spec(width, height, 1, OIIO::TypeDesc::UINT8);
  spec.attribute("png:compressionLevel", 1);
  if (!out->open(path.string(), spec)) throw std::runtime_error(out->geterror());
  const std::vector<unsigned char> row(static_cast<std::size_t>(width), 128);
  for (int y = 0; y < height; ++y)
    if (!out->write_scanline(y, 0, OIIO::TypeDesc::UINT8, row.data())) throw std::runtime_error(out->geterror());
  if (!out->close()) throw std::runtime_error(out->geterror());
}

// CPU seconds (user + system) used by the children waited for so far.
double children_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  const auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + t.tv_usec / 1e6; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

// Runs a failing `nelf ARGS`, checking the one-line contract and that refusing took little work.
// CPU time, not wall time: the suite runs on loaded machines.
void expect_quick_refusal(const TempDir& dir, const std::string& args, const std::string& expected) {
  const double before = children_cpu_seconds();
  expect_clean_failure(dir, args, 1, expected);
  // Decoding the bombs below costs nelf 5 to 30 CPU seconds; refusing one costs its start-up.
  EXPECT_LT(children_cpu_seconds() - before, 3.0) << args;
}

TEST(PixelLimit, A16384SquarePngIsRefusedBeforeDecoding) {
  TempDir dir;
  const auto profile = test::write_small_profile(dir);
  write_flat_png(dir / "bomb.png", 16384, 16384);  // about 1 MB on disk, 268 Mpx
  const std::string bomb = q(dir / "bomb.png");
  const std::string expected =
      "bomb.png: 16384x16384 is 268435456 pixels, more than the limit of 134217728 "
      "(--max-pixels raises it)";
  expect_quick_refusal(dir, "convert " + bomb + " " + q(dir / "out.png") + " --profile " + q(profile), expected);
  expect_quick_refusal(dir, "simulate " + bomb + " -o " + q(dir / "eye.png") + " --profile " + q(profile), expected);
  // probe reads stills through FFmpeg: refused there too, before a frame is decoded.
  expect_quick_refusal(dir, "probe " + bomb, "bomb.png: cannot tell the frame size: the first frame does not decode");
  // As the right view of a pair: each file is checked.
  test::write_test_image(dir / "left.png", test::filled_image(64, 64, {1, 0, 0, 1}), 3);
  expect_quick_refusal(
      dir,
      "convert " + q(dir / "left.png") + " --right " + bomb + " " + q(dir / "out.png") + " --profile " + q(profile),
      expected);
}

TEST(PixelLimit, TheLimitIsAnOptionAndCountsPixels) {
  TempDir dir;
  const auto profile = test::write_small_profile(dir);
  test::write_test_image(dir / "sbs.png", test::filled_image(640, 360, {1, 0, 0, 1}), 3);  // 230400 pixels
  const std::string args = "convert " + q(dir / "sbs.png") + " " + q(dir / "out.png") + " --profile " + q(profile);
  expect_clean_failure(dir, args + " --max-pixels 230399", 1,
                       "sbs.png: 640x360 is 230400 pixels, more than the limit of 230399 (--max-pixels raises it)");
  const auto r = test::run_nelf(args + " --max-pixels 230400");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "out.png"));
  std::filesystem::remove(dir / "out.png");
  // The option is checked like every option: a bad value is a usage error, before any work.
  expect_clean_failure(dir, args + " --max-pixels 0", 2, "--max-pixels");
  expect_clean_failure(dir, args + " --max-pixels lots", 2, "--max-pixels");
}

TEST(PixelLimit, VideoWithHugeFramesIsRefusedBeforeDecoding) {
  TempDir dir;
  const auto profile = test::write_small_profile(dir);
  // 16000x16000 (256 Mpx): as large as FFmpeg itself decodes. The PNG is written row by row and
  // copied into Matroska as it is, so that making it costs a second, not gigabytes.
  write_flat_png(dir / "frame.png", 16000, 16000);
  make_media(dir / "bomb.mkv", "-i " + q(dir / "frame.png") + " -c:v copy");
  std::filesystem::remove(dir / "frame.png");
  const std::string expected =
      "bomb.mkv: video frames: 16000x16000 is 256000000 pixels, more than the limit of "
      "134217728 (--max-pixels raises it)";
  expect_quick_refusal(dir, "probe " + q(dir / "bomb.mkv"), expected);
  expect_quick_refusal(
      dir,
      "convert " + q(dir / "bomb.mkv") + " " + q(dir / "out.mkv") + " --quiet --codec ffv1 --profile " + q(profile),
      expected);
}

TEST(PixelLimit, VideoFramesGrowingMidStreamAreRefused) {
  TempDir dir;
  const auto profile = test::write_small_profile(dir);
  // An MPEG-TS whose H.264 stream switches from 64x36 to 640x360 frames (two streams joined, as a
  // broadcast recording switching channels does); the limit lies between the two sizes.
  make_media(dir / "small.ts", "-f lavfi -i testsrc2=s=64x36:r=10 -frames:v 10 -c:v libx264 -pix_fmt yuv420p");
  make_media(dir / "large.ts", "-f lavfi -i testsrc2=s=640x360:r=10 -frames:v 10 -c:v libx264 -pix_fmt yuv420p");
  test::write_file(dir / "switch.ts", test::read_file(dir / "small.ts") + test::read_file(dir / "large.ts"));
  std::filesystem::remove(dir / "small.ts");
  std::filesystem::remove(dir / "large.ts");
  const std::string args = "convert " + q(dir / "switch.ts") + " " + q(dir / "out.mkv") +
                           " --quiet --codec ffv1 --layout mono --profile " + q(profile);
  expect_clean_failure(dir, args + " --max-pixels 10000", 1,
                       "switch.ts: video frames later in the stream: 640x360 is 230400 pixels, more than the limit "
                       "of 10000 (--max-pixels raises it)");
  // Under a limit both sizes fit, the limit is not what stops it (nelf converts one frame size).
  const auto r = test::run_nelf(args + " --max-pixels 230400");
  EXPECT_EQ(r.err.find("--max-pixels"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the frame size changed mid-stream (64x36 to 640x360)"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace nelf
