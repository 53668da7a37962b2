#include "hmz_output/file_sink_drivers.hpp"

#include <stdexcept>

#include "hmz_output/image_sink.hpp"

namespace nelf {
namespace {

constexpr FileSinkDriver kFileSinks[] = {
    {"raw", "`-`: raw RGBA frames on stdout", is_raw_output, false,
     [](FrameSinkRequest r) { return open_raw_frame_sink(r.raw_fd, r.width, r.height, r.frame_rate); }},
    {"image", "an image sequence (frames_%05d.png) or one image (x.png, .tif, .exr, .jpg)",
     [](const std::string& o) { return is_image_sequence_pattern(o) || is_image_file_name(o); }, false,
     open_image_sequence_sink},
    {"encoded", "any other name: an encoded video file", [](const std::string&) { return true; }, true,
     open_encoded_file_sink},
};

}  // namespace

std::span<const FileSinkDriver> file_sink_drivers() { return kFileSinks; }

const FileSinkDriver& file_sink_driver_for(const std::string& output) {
  for (const FileSinkDriver& driver : kFileSinks)
    if (driver.accepts(output)) return driver;
  throw std::logic_error("no file sink accepts " + output);
}

}  // namespace nelf
