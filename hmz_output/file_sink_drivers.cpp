#include "hmz_output/file_sink_drivers.hpp"

#include <algorithm>
#include <stdexcept>

namespace nelf {

std::span<const FileSinkDriver> file_sink_drivers() {
  const auto all = output_drivers();
  const auto first_file = std::find_if(all.begin(), all.end(), [](const OutputDriver& d) { return !d.live; });
  return all.subspan(static_cast<std::size_t>(first_file - all.begin()));
}

const FileSinkDriver& file_sink_driver_for(const std::string& output) {
  for (const FileSinkDriver& driver : file_sink_drivers())
    if (driver.accepts(output)) return driver;
  throw std::logic_error("no file sink accepts " + output);
}

}  // namespace nelf
