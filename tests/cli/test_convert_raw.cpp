// `nelf convert IN -`: the packed frames as raw 8-bit RGBA on stdout (DESIGN.md §7), read by the
// ffmpeg tools as `-f rawvideo -pixel_format rgba`; the same pixels the image sequence holds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "support/image_files.hpp"
#include "support/test_support.hpp"

namespace nelf::test {
namespace {

constexpr std::size_t kPackedBytes = 1280u * 1470u * 4u;  // hmz-t1 on hdmi-fp-720p60

TEST(ConvertRaw, WritesEveryPackedFrameAsRgbaOnStdoutAndSaysTheFormatOnStderr) {
  TempDir dir;
  const auto raw = dir / "frames.rgba";
  const auto r = run_nelf("convert synthetic:duration=1 - --quiet > " + q(raw));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(std::filesystem::file_size(raw), 24 * kPackedBytes);  // 1 s at 24 fps
  EXPECT_EQ(r.err,
            "nelf: raw video to stdout: rgba 1280x1470 at 24 fps (e.g. | ffplay -f rawvideo -pixel_format rgba "
            "-video_size 1280x1470 -framerate 24 -)\n");
  // ffprobe, given what that line says, finds 24 frames of that size.
  const auto probe = run_command(
      "ffprobe -v error -f rawvideo -pixel_format rgba -video_size 1280x1470 -framerate 24 -count_frames "
      "-show_entries stream=width,height,nb_read_frames -of csv=p=0 " +
      q(raw));
  ASSERT_EQ(probe.status, 0) << probe.err;
  EXPECT_EQ(probe.out, "1280,1470,24\n");
}

TEST(ConvertRaw, HoldsTheSamePixelsAsTheImageSequence) {
  TempDir dir;
  const auto raw = dir / "frames.rgba";
  ASSERT_EQ(run_nelf("convert synthetic:duration=0.125 - --quiet > " + q(raw)).status, 0);
  const auto png = run_nelf("convert synthetic:duration=0.125 " + q(dir / "f_%02d.png") + " --quiet");
  ASSERT_EQ(png.status, 0) << png.err;
  const std::string bytes = read_file(raw);
  ASSERT_EQ(bytes.size(), 3 * kPackedBytes);
  for (int frame = 0; frame < 3; ++frame) {
    const auto image = read_back(dir / ("f_0" + std::to_string(frame + 1) + ".png"));
    ASSERT_EQ(image.width, 1280);
    ASSERT_EQ(image.height, 1470);
    int worst = 0;
    for (int y = 0; y < image.height; y += 7)
      for (int x = 0; x < image.width; x += 3)
        for (int c = 0; c < std::min(image.channels, 3); ++c) {
          const auto at = frame * kPackedBytes + (static_cast<std::size_t>(y) * 1280 + x) * 4 + c;
          const int expected = static_cast<int>(std::lround(image.at(x, y, c) * 255.f));
          worst = std::max(worst, std::abs(static_cast<unsigned char>(bytes[at]) - expected));
        }
    EXPECT_EQ(worst, 0) << "frame " << frame;
  }
}

TEST(ConvertRaw, AStillIsOneFrame) {
  TempDir dir;
  const Image jps = filled_image(64, 32, Rgba{0.8f, 0.2f, 0.1f, 1.f});
  write_test_image(dir / "photo.jps", jps, 3, OIIO::TypeDesc::UINT8, "jpeg");
  const auto raw = dir / "photo.rgba";
  const auto r = run_nelf("convert " + q(dir / "photo.jps") + " - > " + q(raw));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(std::filesystem::file_size(raw), kPackedBytes);
  EXPECT_NE(r.err.find("rgba 1280x1470 at 1 fps"), std::string::npos) << r.err;
}

// A reader that stops early ends nelf quietly (as `yes | head` does), with nothing left behind.
TEST(ConvertRaw, AReaderThatLeavesEndsItQuietly) {
  TempDir dir;
  const auto piped =
      run_command("bash -c " + shell_quote("cd " + q(dir.path()) + " && " + std::string(NELF_BINARY) +
                                           " convert synthetic:duration=2 - --quiet | head -c 1000 > /dev/null; "
                                           "echo ${PIPESTATUS[0]}"));
  EXPECT_EQ(piped.out, "141\n") << piped.err;
  EXPECT_EQ(piped.err.find("nelf: error"), std::string::npos) << piped.err;
  EXPECT_TRUE(files_in(dir.path()).empty());
}

// What raw frames cannot have is refused, not ignored.
TEST(ConvertRaw, OptionsItCannotHonourAreRefused) {
  TempDir dir;
  for (const std::string option : {"--codec ffv1", "--crf 18", "--bits 16"}) {
    const auto r = run_nelf("convert synthetic:duration=1 - " + option);
    EXPECT_EQ(r.status, 2) << option;
    EXPECT_EQ(r.err, "nelf: " + option.substr(0, option.find(' ')) +
                         " does not apply to - (raw 8-bit RGBA frames on stdout)\n");
    EXPECT_TRUE(r.out.empty());
  }
}

}  // namespace
}  // namespace nelf::test
