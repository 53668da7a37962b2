#pragma once
// The inputs nelf reads, as a table: each row names a driver, says which requests it takes and opens
// them. open_source() walks it in order; the FFmpeg file driver is last and takes everything else.
// A new kind of input is one file (inputs/<name>_driver.cpp) and one row in source_drivers.cpp.
#include <memory>
#include <span>
#include <string_view>

#include "inputs/source.hpp"

namespace nelf {

struct SourceDriver {
  std::string_view name;
  std::string_view help;  // one line: what the input is and how it is named
  bool (*accepts)(const SourceRequest& request);
  // Throws UserError (one line): status 1 for inputs that cannot be used, 2 for options that
  // contradict the input.
  std::unique_ptr<Source> (*open)(const SourceRequest& request);
};

// The rows, in the order open_source() tries them.
std::span<const SourceDriver> source_drivers();

// The first row that accepts `request`.
const SourceDriver& source_driver_for(const SourceRequest& request);

// Opens the input (and --right) with the first driver that accepts it; a file's layout is detected
// from its first frame, and one line describing the input is printed unless quiet. Throws
// UserError: status 1 for inputs that cannot be used, 2 for options that contradict the input (the
// same messages in play and convert).
std::unique_ptr<Source> open_source(const SourceRequest& request);

}  // namespace nelf
