#include "hmz_output/display_drivers.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "hmz_output/kms_display.hpp"
#include "hmz_output/window_display.hpp"

namespace nelf {

// Outputs that are one file with no header of their own declare their opener here, beside their row.
std::unique_ptr<Display> open_offscreen_display(const DisplayOptions& options);
std::unique_ptr<Display> open_quad_buffer_display(const DisplayOptions& options);

namespace {

constexpr DisplayDriver kDrivers[] = {
    {"window", "a desktop window, the packed frame scaled to fit",
     [](const DisplayOptions& o) { return open_window_display(o, WindowMode::window); }},
    {"fullscreen", "1:1 on the monitor --monitor names, the HMD by default",
     [](const DisplayOptions& o) { return open_window_display(o, WindowMode::fullscreen); }},
    {"kms", "scan-out on the --connector without a desktop (docs/kms.md)", open_kms_display},
    {"quad-buffer", "an OpenGL quad-buffer stereo window, an eye in each back buffer", open_quad_buffer_display},
    {"offscreen", "no display: rendered off screen and paced by the clock, for tests and timing",
     open_offscreen_display},
};

}  // namespace

std::span<const DisplayDriver> display_drivers() { return kDrivers; }

const DisplayDriver* find_display_driver(std::string_view name) {
  for (const DisplayDriver& driver : kDrivers)
    if (driver.name == name) return &driver;
  return nullptr;
}

const DisplayDriver& display_driver(std::string_view name) {
  if (const DisplayDriver* driver = find_display_driver(name)) return *driver;
  throw std::invalid_argument(fmt::format("unknown output '{}' (expected {})", name, display_driver_names()));
}

std::string display_driver_names() {
  std::string names;
  const std::size_t count = std::size(kDrivers);
  for (std::size_t i = 0; i < count; ++i) {
    if (i > 0) names += i + 1 == count ? " or " : ", ";
    names += kDrivers[i].name;
  }
  return names;
}

std::string display_driver_help() {
  std::string help;
  for (const DisplayDriver& driver : kDrivers) {
    if (!help.empty()) help += "; ";
    help += fmt::format("{} ({})", driver.name, driver.help);
  }
  return help;
}

}  // namespace nelf
