// open_kms_display's errors that need no DRM device (there is none where the tests run): a
// missing, non-DRM or folder NELF_DRM_DEVICE, no /dev/dri at all, and the wording of the
// permission and display-server errors.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cerrno>
#include <optional>

#include "hmz_output/kms_display.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::ScopedEnv;

DisplayOptions kms_options() {
  DisplayOptions o;
  o.signal = *find_signal("hdmi-fp-720p60");
  o.packed = {1280, 1470};
  return o;
}

std::string open_error() {
  try {
    open_kms_display(kms_options());
  } catch (const KmsError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(KmsDisplay, FindsCardNodesInNumericOrder) {
  test::TempDir dir;
  for (const char* name : {"card10", "card1", "renderD128", "card0", "cardX", "card"}) test::write_file(dir / name, "");
  const auto cards = find_drm_cards(dir.path());
  ASSERT_EQ(cards.size(), 3u);
  EXPECT_EQ(cards[0].filename(), "card0");
  EXPECT_EQ(cards[1].filename(), "card1");
  EXPECT_EQ(cards[2].filename(), "card10");
  EXPECT_TRUE(find_drm_cards(dir / "missing").empty());
}

TEST(KmsDisplay, NoDrmDeviceSaysSoAndSuggestsAWindow) {
  ScopedEnv env("NELF_DRM_DEVICE", nullptr);
  if (!find_drm_cards().empty()) GTEST_SKIP() << "this machine has /dev/dri/card*";
  EXPECT_EQ(open_error(),
            "no DRM device (no /dev/dri/card*): --output kms needs a GPU with a kernel modesetting driver on this "
            "machine; use --output window");
}

TEST(KmsDisplay, MissingDeviceFromTheEnvironment) {
  test::TempDir dir;
  const std::string path = (dir / "card7").string();
  ScopedEnv env("NELF_DRM_DEVICE", path.c_str());
  EXPECT_EQ(open_error(), "NELF_DRM_DEVICE=" + path +
                              ": no such device; set NELF_DRM_DEVICE to a card node such as /dev/dri/card0, or "
                              "unset it");
}

TEST(KmsDisplay, RegularFileIsNotADrmDevice) {
  test::TempDir dir;
  const std::string path = (dir / "card0").string();
  test::write_file(path, "not a device");
  ScopedEnv env("NELF_DRM_DEVICE", path.c_str());
  EXPECT_EQ(open_error(), "NELF_DRM_DEVICE=" + path +
                              " is not a DRM device (not a character device); point it at a card node such as "
                              "/dev/dri/card0");
}

TEST(KmsDisplay, OtherCharacterDeviceIsNotADrmDevice) {
  ScopedEnv env("NELF_DRM_DEVICE", "/dev/null");
  const std::string error = open_error();
  EXPECT_EQ(error.rfind("NELF_DRM_DEVICE=/dev/null is not a DRM device (DRM_IOCTL_VERSION: ", 0), 0u) << error;
  EXPECT_NE(error.find("point it at a card node"), std::string::npos) << error;
}

TEST(KmsDisplay, FolderIsNotADrmDevice) {
  test::TempDir dir;
  ScopedEnv env("NELF_DRM_DEVICE", dir.path().c_str());
  EXPECT_EQ(open_error(), "NELF_DRM_DEVICE=" + dir.path().string() +
                              " is a folder, not a DRM device; point it at a card node such as /dev/dri/card0");
}

// Root opens anything, so the permission error is checked through the function that words it.
TEST(KmsDisplay, PermissionDeniedSuggestsTheVideoGroupOrAConsole) {
  EXPECT_EQ(kms_open_error("/dev/dri/card0", EACCES, false),
            "permission denied opening /dev/dri/card0: add your user to the 'video' group (sudo usermod -aG video "
            "$USER, then log in again) or run nelf from a text console (Ctrl+Alt+F3)");
  EXPECT_NE(kms_open_error("/dev/dri/card0", EPERM, true).find("NELF_DRM_DEVICE=/dev/dri/card0"), std::string::npos);
}

TEST(KmsDisplay, DisplayServerHoldingTheDevice) {
  for (const int error : {EACCES, EPERM, EBUSY}) {
    const std::string m = kms_master_error("/dev/dri/card0", "become DRM master", error);
    EXPECT_EQ(m.rfind("cannot become DRM master on /dev/dri/card0 (", 0), 0u) << m;
    EXPECT_NE(m.find("a display server (X or Wayland) holds the device; stop the display server or switch to a text "
                     "console (Ctrl+Alt+F3)"),
              std::string::npos)
        << m;
  }
  EXPECT_EQ(kms_master_error("/dev/dri/card0", "set the 3D mode on HDMI-A-1", EINVAL).find("display server"),
            std::string::npos);
}

}  // namespace
}  // namespace nelf
