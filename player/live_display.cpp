#include "player/live_display.hpp"

#include <stdexcept>

#include "core/user_error.hpp"
#include "hmz_output/display_drivers.hpp"

namespace nelf {

std::unique_ptr<Display> open_live_display(const LiveDisplayRequest& request, const Profile& profile,
                                           const Signal& signal) {
  DisplayOptions options;
  options.signal = signal;
  const auto panel = profile.display.resolution;
  options.packed = {signal.packed_width(panel[0]), signal.packed_height(panel[1])};
  options.monitor = request.monitor;
  options.connector = request.connector;
  options.title = request.title;
  options.gpu = request.gpu;
  options.keys_from_stdin = request.keys_from_stdin;
  const DisplayDriver* driver = nullptr;
  try {
    driver = &display_driver(request.output);
  } catch (const std::invalid_argument& e) {
    throw UserError(e.what(), 2);
  }
  try {
    return driver->open_display(options);
  } catch (const std::exception& e) {
    throw UserError(e.what(), 1);
  }
}

}  // namespace nelf
