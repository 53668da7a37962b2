// The device driver: FFmpeg's capture devices through libavdevice, read live by the file driver's
// source (inputs/file_driver.cpp) with the same layout rules: `v4l2:/dev/videoN` (an HDMI capture
// card: a console's side-by-side or frame-packed 3D) and `device:FORMAT:INPUT` for any other input
// device FFmpeg knows (x11grab, kmsgrab, lavfi, …; `ffmpeg -devices` lists them), INPUT being that
// device's own name for what it reads.
#include <fmt/format.h>

#include <memory>
#include <string>

#include "core/printable.hpp"
#include "core/user_error.hpp"
#include "inputs/source.hpp"

namespace nelf::drivers {

std::unique_ptr<Source> open_ffmpeg_device(const SourceRequest& request, const std::string& device,
                                           const std::string& device_input);

bool accepts_device(const SourceRequest& request) {
  return request.input.rfind("v4l2:", 0) == 0 || request.input.rfind("device:", 0) == 0;
}

std::unique_ptr<Source> open_device(const SourceRequest& request) {
  const std::string& input = request.input;
  std::string device, device_input;
  if (input.rfind("v4l2:", 0) == 0) {
    device = "v4l2";
    device_input = input.substr(5);
    if (device_input.empty()) throw UserError("v4l2: name the device, e.g. v4l2:/dev/video0", 2);
  } else {
    const std::size_t colon = input.find(':', 7);
    device = input.substr(7, colon == std::string::npos ? std::string::npos : colon - 7);
    device_input = colon == std::string::npos ? std::string() : input.substr(colon + 1);
    if (device.empty())
      throw UserError(fmt::format("{}: name the device as device:FORMAT:INPUT (ffmpeg -devices lists the formats)",
                                  printable(input)),
                      2);
  }
  return open_ffmpeg_device(request, device, device_input);
}

}  // namespace nelf::drivers
