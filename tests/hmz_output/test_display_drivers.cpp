// The table of live outputs (hmz_output/display_drivers): --output's values, its help and the
// "unknown output" error all come from it.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>
#include <string>

#include "hmz_output/display_drivers.hpp"

namespace nelf {
namespace {

TEST(DisplayDrivers, EveryRowHasAUniqueNameHelpAndOpener) {
  std::set<std::string_view> names;
  for (const DisplayDriver& driver : display_drivers()) {
    EXPECT_FALSE(driver.name.empty());
    EXPECT_FALSE(driver.help.empty()) << driver.name;
    EXPECT_NE(driver.open_display, nullptr) << driver.name;
    EXPECT_TRUE(names.insert(driver.name).second) << driver.name << " twice";
    EXPECT_EQ(find_display_driver(driver.name), &driver);
  }
  for (const char* name : {"window", "fullscreen", "kms", "quad-buffer", "offscreen"})
    EXPECT_TRUE(names.count(name)) << name;
}

TEST(DisplayDrivers, AnUnknownNameListsTheOutputsOfTheTable) {
  EXPECT_EQ(find_display_driver("hdmi"), nullptr);
  try {
    display_driver("hdmi");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "unknown output 'hdmi' (expected " + display_driver_names() + ")");
  }
  EXPECT_EQ(display_driver_names(), "window, fullscreen, kms, quad-buffer or offscreen");
  const std::string help = display_driver_help();
  for (const DisplayDriver& driver : display_drivers())
    EXPECT_NE(help.find(std::string(driver.name) + " (" + std::string(driver.help) + ")"), std::string::npos);
}

}  // namespace
}  // namespace nelf
