// The live-output contract (hmz_output/display.hpp), run against every row of the output table
// (the live rows of hmz_output/output_drivers.cpp) on a private Xvfb server: an output either opens and behaves as
// the player needs — the packed framebuffer of the size asked for, its texture behind it, a
// context that can be made current, present() and poll_events() that work, a description, a
// refresh rate — or refuses with one line naming what to do. A new row is covered without a line
// here; each row must end up in one of the two cases this machine allows (listed below).
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>

#include "hmz_output/display_drivers.hpp"
#include "support/xvfb.hpp"

namespace nelf {
namespace {

DisplayOptions frame_packed_options() {
  DisplayOptions options;
  options.signal = *find_signal("hdmi-fp-720p60");
  options.packed = {options.signal.packed_width(1280), options.signal.packed_height(720)};
  options.title = "nelf conformance";
  return options;
}

// On Xvfb with Mesa: what each output does. Fullscreen needs a monitor in the packed mode (Xvfb's
// screen is not 1280x1470), KMS a DRM device, quad-buffer stereo visuals (Mesa has none).
const std::map<std::string, bool>& opens_here() {
  static const std::map<std::string, bool> expected = {
      {"window", true}, {"fullscreen", false}, {"kms", false}, {"quad-buffer", false}, {"offscreen", true},
  };
  return expected;
}

bool has_drm_device() {
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator("/dev/dri", error))
    if (entry.path().filename().string().rfind("card", 0) == 0) return true;
  return false;
}

class DisplayConformance : public ::testing::TestWithParam<std::string> {
 protected:
  test::XvfbServer xvfb_;
  test::ScopedDisplay display_env_{xvfb_.display_name()};
};

TEST_P(DisplayConformance, OpensAndKeepsTheContractOrRefusesInOneLine) {
  const DisplayDriver& driver = display_driver(GetParam());
  ASSERT_TRUE(opens_here().count(std::string(driver.name)))
      << "a new output: say here whether it opens on Xvfb with Mesa";
  if (driver.name == "kms" && has_drm_device())
    GTEST_SKIP() << "a DRM device is here: what KMS does then depends on it (tests/hmz_output/test_kms_*.cpp cover its "
                    "choices and errors)";
  const DisplayOptions options = frame_packed_options();
  std::unique_ptr<Display> display;
  std::string refusal;
  try {
    display = driver.open_display(options);
  } catch (const std::exception& e) {
    refusal = e.what();
  }
  if (!opens_here().at(std::string(driver.name))) {
    ASSERT_FALSE(display) << driver.name << " opened here";
    EXPECT_FALSE(refusal.empty());
    // The first line is what the user reads; it names a way on: an option (--output kms,
    // --monitor NAME). (A monitor in the wrong mode adds the xrandr commands on later lines.)
    const std::string first_line = refusal.substr(0, refusal.find('\n'));
    EXPECT_NE(first_line.find(" --"), std::string::npos) << refusal;
    return;
  }
  ASSERT_TRUE(display) << driver.name << ": " << refusal;

  display->context()->make_current();
  EXPECT_EQ(display->packed_size(), options.packed);
  const GLuint fbo = display->packed_framebuffer();
  ASSERT_NE(fbo, 0u);
  EXPECT_EQ(glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER), static_cast<GLenum>(GL_FRAMEBUFFER_COMPLETE));
  GLint width = 0, height = 0;
  glGetTextureLevelParameteriv(display->packed_texture(), 0, GL_TEXTURE_WIDTH, &width);
  glGetTextureLevelParameteriv(display->packed_texture(), 0, GL_TEXTURE_HEIGHT, &height);
  EXPECT_EQ(width, options.packed[0]);
  EXPECT_EQ(height, options.packed[1]);
  GLint attached = 0;
  glGetNamedFramebufferAttachmentParameteriv(fbo, GL_COLOR_ATTACHMENT0, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME,
                                             &attached);
  EXPECT_EQ(static_cast<GLuint>(attached), display->packed_texture()) << "the texture is what the framebuffer holds";

  const GLfloat grey[4] = {0.5f, 0.5f, 0.5f, 1.f};
  for (int i = 0; i < 3; ++i) {
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, grey);
    EXPECT_NO_THROW(display->present());
    EXPECT_NO_THROW(display->poll_events());
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  EXPECT_FALSE(display->close_requested());
  EXPECT_GT(display->refresh_hz(), 0.0);
  EXPECT_NE(display->description().find("1280x1470"), std::string::npos) << display->description();
  EXPECT_FALSE(display->toggle_fullscreen().empty()) << "f answers with a message, done or not";
}

std::vector<std::string> every_output() {
  std::vector<std::string> names;
  for (const DisplayDriver& driver : display_drivers()) names.emplace_back(driver.name);
  return names;
}

// Test names from the output names ("quad-buffer" → quad_buffer).
std::string output_test_name(const ::testing::TestParamInfo<std::string>& param) {
  std::string name = param.param;
  for (char& c : name)
    if (c == '-') c = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(EveryOutput, DisplayConformance, ::testing::ValuesIn(every_output()), output_test_name);

}  // namespace
}  // namespace nelf
