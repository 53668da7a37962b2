#include "hmz_output/display_drivers.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace nelf {

std::span<const DisplayDriver> display_drivers() {
  const auto all = output_drivers();
  const auto first_file = std::find_if(all.begin(), all.end(), [](const OutputDriver& d) { return !d.live; });
  return all.first(static_cast<std::size_t>(first_file - all.begin()));
}

const DisplayDriver* find_display_driver(std::string_view name) {
  for (const DisplayDriver& driver : display_drivers())
    if (driver.name == name) return &driver;
  return nullptr;
}

const DisplayDriver& display_driver(std::string_view name) {
  if (const DisplayDriver* driver = find_display_driver(name)) return *driver;
  throw std::invalid_argument(fmt::format("unknown output '{}' (expected {})", name, display_driver_names()));
}

std::string display_driver_names() {
  std::string names;
  const auto drivers = display_drivers();
  const std::size_t count = drivers.size();
  for (std::size_t i = 0; i < count; ++i) {
    if (i > 0) names += i + 1 == count ? " or " : ", ";
    names += drivers[i].name;
  }
  return names;
}

std::string display_driver_help() {
  std::string help;
  for (const DisplayDriver& driver : display_drivers()) {
    if (!help.empty()) help += "; ";
    help += fmt::format("{} ({})", driver.name, driver.help);
  }
  return help;
}

}  // namespace nelf
