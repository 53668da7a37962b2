#pragma once
// The file outputs of `nelf convert` for video: the rows of hmz_output/output_drivers.cpp that
// are not live, chosen by the output name: the first row whose test accepts it (the encoded file
// last, as it takes any name).
#include <span>
#include <string>

#include "hmz_output/output_drivers.hpp"

namespace nelf {

using FileSinkDriver = OutputDriver;

std::span<const FileSinkDriver> file_sink_drivers();

// The first file row that accepts `output`; every name has one.
const FileSinkDriver& file_sink_driver_for(const std::string& output);

}  // namespace nelf
