#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "hmz_output/frame_sink.hpp"
#include "hmz_output/image_sink.hpp"
#include "support/image_files.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::files_in;
using test::TempDir;

std::string write_error(const Image& image, const std::filesystem::path& path, ImageWriteOptions options = {}) {
  try {
    write_image_file(image, path, options);
  } catch (const ImageWriteError& e) {
    return e.what();
  }
  return "";
}

Image gradient(int w, int h) {
  Image image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      image.at(x, y) = {static_cast<float>(x) / (w - 1), static_cast<float>(y) / (h - 1), 0.25f, 1.f};
  return image;
}

TEST(ImageSink, WritesPng8And16Bit) {
  TempDir dir;
  const Image image = gradient(300, 7);
  write_image_file(image, dir / "out.png", {});
  auto back = test::read_back(dir / "out.png");
  EXPECT_EQ(back.width, 300);
  EXPECT_EQ(back.height, 7);
  EXPECT_EQ(back.channels, 3);
  EXPECT_NEAR(back.at(150, 3, 0), 150.f / 299.f, 0.5f / 255.f + 1e-6f);
  EXPECT_NEAR(back.at(0, 6, 1), 1.f, 1e-6f);

  write_image_file(image, dir / "deep.png", {false, 16});
  back = test::read_back(dir / "deep.png");
  EXPECT_NEAR(back.at(150, 3, 0), 150.f / 299.f, 0.5f / 65535.f + 1e-6f);
  EXPECT_EQ(files_in(dir.path()), (std::vector<std::string>{"deep.png", "out.png"}));
}

TEST(ImageSink, WritesTiffExrJpegByExtension) {
  TempDir dir;
  const Image image = gradient(16, 9);
  for (const char* name : {"a.tif", "b.TIFF", "c.exr", "d.jpg", "e.jpeg"}) {
    write_image_file(image, dir / name, {});
    const auto back = test::read_back(dir / name);
    EXPECT_EQ(back.width, 16) << name;
    EXPECT_NEAR(back.at(8, 4, 2), 0.25f, 0.02f) << name;
  }
  EXPECT_EQ(files_in(dir.path()).size(), 5u);
}

TEST(ImageSink, RefusesToOverwriteWithoutPermission) {
  TempDir dir;
  test::write_file(dir / "out.png", "precious");
  EXPECT_EQ(write_error(gradient(4, 4), dir / "out.png"), (dir / "out.png").string() + " exists; pass -y to overwrite");
  EXPECT_EQ(test::read_file(dir / "out.png"), "precious");
  write_image_file(gradient(4, 4), dir / "out.png", {true, 8});
  EXPECT_EQ(test::read_back(dir / "out.png").width, 4);
  EXPECT_EQ(files_in(dir.path()), std::vector<std::string>{"out.png"});
}

TEST(ImageSink, ClearErrorsAndNothingLeftBehind) {
  TempDir dir;
  const Image image = gradient(4, 4);
  EXPECT_NE(write_error(image, dir / "out.bmpx").find("unknown image extension '.bmpx'"), std::string::npos);
  EXPECT_NE(write_error(image, dir / "missing" / "out.png").find("does not exist"), std::string::npos);
  test::write_file(dir / "file", "");
  EXPECT_NE(write_error(image, dir / "file" / "out.png").find("does not exist"), std::string::npos);
  EXPECT_NE(write_error(image, dir / "out.jpg", {false, 16}).find("16-bit output needs .png or .tif"),
            std::string::npos);
  EXPECT_NE(write_error(image, dir / "out.png", {false, 12}).find("must be 8 or 16"), std::string::npos);
  EXPECT_NE(write_error(Image(), dir / "out.png").find("empty image"), std::string::npos);
  std::filesystem::create_directory(dir / "sub.png");
  EXPECT_NE(write_error(image, dir / "sub.png", {true, 8}).find("is a directory"), std::string::npos);
  EXPECT_EQ(files_in(dir.path()), (std::vector<std::string>{"file", "sub.png"}));
}

TEST(ImageSink, OverLargeJpegIsRefusedBeforeWriting) {
  TempDir dir;
  // libjpeg would exit the process on an image wider than 65500 pixels.
  const std::string e = write_error(Image(65536, 1), dir / "wide.jpg");
  EXPECT_NE(e.find("wide.jpg: 65536x1 exceeds JPEG's limit"), std::string::npos) << e;
  EXPECT_TRUE(files_in(dir.path()).empty());
}

// An output names an image sequence when its file name holds a printf conversion of the frame
// number, as printf reads it: %d with an optional width; %% is a literal %.
TEST(ImageSink, SequencePatternsAreAFrameNumbersConversion) {
  for (const char* name : {"f_%d.png", "f_%03d.png", "%4d.tif", "take_%2d.exr", "100%%_%d.png"})
    EXPECT_TRUE(is_image_sequence_pattern(name)) << name;
  for (const char* name :
       {"f.png", "100%.png", "a%b.png", "f_%0x.png", "f_%s.png", "frames_%d/one.png", "f_%", "x%%d.png"})
    EXPECT_FALSE(is_image_sequence_pattern(name)) << name;
}

}  // namespace
}  // namespace nelf
