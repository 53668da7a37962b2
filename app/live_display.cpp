#include "app/live_display.hpp"

#include <stdexcept>

#include "app/commands.hpp"
#include "hmz_output/kms_display.hpp"
#include "hmz_output/window_display.hpp"

namespace nelf::app {

std::unique_ptr<Display> open_live_display(const LiveDisplayRequest& request, const Profile& profile,
                                           const Signal& signal) {
  DisplayOptions options;
  options.kind = request.kind;
  options.signal = signal;
  const auto panel = profile.display.resolution;
  options.packed = {signal.packed_width(panel[0]), signal.packed_height(panel[1])};
  options.monitor = request.monitor;
  options.connector = request.connector;
  options.title = request.title;
  try {
    return request.kind == OutputKind::kms ? open_kms_display(options) : open_window_display(options);
  } catch (const std::exception& e) {
    throw UserError(e.what(), 1);
  }
}

}  // namespace nelf::app
