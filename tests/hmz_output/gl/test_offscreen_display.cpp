// The offscreen output (hmz_output/offscreen_display.cpp) on an EGL context: what the player needs
// of a display, with no display server.
#include <gtest/gtest.h>

#include <array>
#include <stdexcept>

#include "hmz_output/display_drivers.hpp"

namespace nelf {
namespace {

// The offscreen output needs no display server: an EGL context, a packed framebuffer of the size
// asked for, no keys, never closed by itself, paced at the signal's refresh rate.
TEST(DisplayDrivers, OffscreenOpensWithoutADisplayServer) {
  DisplayOptions options;
  options.signal = *find_signal("hdmi-fp-720p60");
  options.packed = {options.signal.packed_width(1280), options.signal.packed_height(720)};
  const auto display = display_driver("offscreen").open_display(options);
  EXPECT_EQ(display->packed_size(), (std::array<int, 2>{1280, 1470}));
  EXPECT_NE(display->packed_framebuffer(), 0u);
  EXPECT_NE(display->packed_texture(), 0u);
  EXPECT_FALSE(display->vsync());
  EXPECT_NEAR(display->refresh_hz(), 60.0, 0.1);
  EXPECT_TRUE(display->poll_events().empty());
  EXPECT_FALSE(display->close_requested());
  EXPECT_NO_THROW(display->present());
  EXPECT_EQ(display->description().rfind("offscreen 1280x1470 (", 0), 0u) << display->description();
  options.packed = {0, 0};
  EXPECT_THROW(display_driver("offscreen").open_display(options), std::invalid_argument);
}

}  // namespace
}  // namespace nelf
