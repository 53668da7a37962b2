#pragma once
// The file outputs of `nelf convert` for video, chosen by the output name: the first row whose
// test accepts it (the encoded file last, as it takes any name). A new kind of output is its sink's
// own file plus one row in file_sink_drivers.cpp.
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "hmz_output/frame_sink.hpp"

namespace nelf {

struct FileSinkDriver {
  std::string_view name;  // of the row, for tests and messages
  std::string_view help;  // which output names it takes, a few words
  bool (*accepts)(const std::string& output);
  // Whether the sink writes the source's streams (FrameSinkRequest::carried, ::audio): the caller
  // opens them only for such a row.
  bool carries_streams;
  std::unique_ptr<FrameSink> (*open)(FrameSinkRequest request);
};

std::span<const FileSinkDriver> file_sink_drivers();

// The first row that accepts `output`; every name has one.
const FileSinkDriver& file_sink_driver_for(const std::string& output);

}  // namespace nelf
