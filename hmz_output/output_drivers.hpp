#pragma once
// Every output of nelf, one row each in output_drivers.cpp: the live ones (`nelf play` and
// `nelf calibrate --output`: display_drivers.hpp) and the files `nelf convert` writes
// (file_sink_drivers.hpp). A new output is its own file plus one row.
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "hmz_output/display.hpp"
#include "hmz_output/frame_sink.hpp"

namespace nelf {

struct OutputDriver {
  std::string_view name;  // a live row: the --output value; a file row: its name in tests
  std::string_view help;  // what it shows, or which output names it takes, a few words for --help
  // Shows frames as they come (a Display) rather than writing a file (a FrameSink).
  bool live;
  // A live row: opens the display; throws std::runtime_error (one line) when it cannot.
  std::unique_ptr<Display> (*open_display)(const DisplayOptions& options);
  // A file row: whether it takes the output name `output` (rows are asked in order).
  bool (*accepts)(const std::string& output);
  // A file row: whether the sink writes the source's streams (FrameSinkRequest::carried, ::audio):
  // the caller opens them only for such a row.
  bool carries_streams;
  // A file row: opens the sink.
  std::unique_ptr<FrameSink> (*open_file)(FrameSinkRequest request);
};

// All rows, the live ones first.
std::span<const OutputDriver> output_drivers();

}  // namespace nelf
