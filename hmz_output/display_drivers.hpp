#pragma once
// The live outputs `nelf play --output` and `nelf calibrate --output` choose from: one row each in
// output_drivers.cpp. The option's help, its check and the "unknown output" error are made from
// the table, so a new output is its own file plus one row.
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "hmz_output/output_drivers.hpp"

namespace nelf {

using DisplayDriver = OutputDriver;

// The live rows of hmz_output/output_drivers.cpp.
std::span<const DisplayDriver> display_drivers();

// The driver called `name`, or nullptr.
const DisplayDriver* find_display_driver(std::string_view name);

// Like find_display_driver, but throws std::invalid_argument "unknown output 'NAME' (expected
// window, fullscreen, …)" for a name no row has.
const DisplayDriver& display_driver(std::string_view name);

// "window, fullscreen, quad-buffer, kms or offscreen": for messages that list the outputs.
std::string display_driver_names();

// "window (a desktop window …), fullscreen (…), …": for --help.
std::string display_driver_help();

}  // namespace nelf
