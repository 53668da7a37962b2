// OpenImageIO as a module loaded on first use (core/image_library.hpp): commands that read or
// write no image file run without it, and one that needs it but cannot load it fails with one
// clear line and leaves nothing behind.
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>

#include "support/image_files.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::ScopedEnv;

using test::files_in;
using test::run_command;
using test::run_nelf;
using test::q;
using test::shell_quote;
using test::TempDir;

TEST(ImageLibrary, TheNelfBinaryDoesNotLinkOpenImageIO) {
  const auto r = run_command("ldd " + shell_quote(NELF_BINARY));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("libavcodec"), std::string::npos) << r.out;  // ldd did list the libraries
  EXPECT_EQ(r.out.find("OpenImageIO"), std::string::npos) << r.out;
}

TEST(ImageLibrary, VideoConversionAndProbeRunWithoutIt) {
  TempDir dir;
  const ScopedEnv no_module("NELF_IMAGE_LIBRARY", (dir / "no-such-module.so").string());
  const auto converted = run_nelf("convert synthetic:duration=0.25,size=160x90 " + q(dir / "out.mkv") + " --profile " +
                                  q(test::write_small_profile(dir)) + " --quiet");
  EXPECT_EQ(converted.status, 0) << converted.err;
  const auto probed = run_nelf("probe " + q(dir / "out.mkv"));
  EXPECT_EQ(probed.status, 0) << probed.err;
}

TEST(ImageLibrary, AMissingModuleIsOneClearLineAndNoOutput) {
  TempDir dir;
  const auto input = dir / "in.png";
  test::write_test_image(input, test::filled_image(64, 32, {0.5f, 0.2f, 0.1f, 1.f}), 3);
  const auto profile = test::write_small_profile(dir);
  const ScopedEnv no_module("NELF_IMAGE_LIBRARY", (dir / "no-such-module.so").string());
  test::expect_clean_failure(
      dir, "convert " + q(input) + " " + q(dir / "out.png") + " --profile " + q(profile), 1,
      "cannot load nelf's image library " + (dir / "no-such-module.so").string() + ": cannot open shared object file");
}

TEST(ImageLibrary, AModuleFromSomethingElseIsRefused) {
  TempDir dir;
  const auto input = dir / "in.png";
  test::write_test_image(input, test::filled_image(64, 32, {0.5f, 0.2f, 0.1f, 1.f}), 3);
  const auto profile = test::write_small_profile(dir);
  // A real shared object without the module's entry point.
  const auto libm = run_command("ldconfig -p | awk '/libm.so.6 .*x86-64/ {print $NF; exit}'");
  ASSERT_EQ(libm.status, 0);
  std::string path = libm.out.substr(0, libm.out.find('\n'));
  if (path.empty()) GTEST_SKIP() << "no libm.so.6 in ldconfig's cache";
  const ScopedEnv other("NELF_IMAGE_LIBRARY", path);
  test::expect_clean_failure(dir, "convert " + q(input) + " " + q(dir / "out.png") + " --profile " + q(profile), 1,
                             "is not the image library of this nelf build");
}

}  // namespace
}  // namespace nelf
