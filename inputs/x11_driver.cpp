// The x11 driver: `x11:` (the screen), `x11:window=TITLE`, `x11:window-id=0x…` — a live X11 window
// as a stereo source (inputs/x11_capture, inputs/live_capture.hpp).
#include <memory>

#include "inputs/live_capture.hpp"
#include "inputs/source.hpp"
#include "inputs/x11_capture.hpp"

namespace nelf::drivers {

bool accepts_x11(const SourceRequest& request) { return is_x11_capture_spec(request.input); }

std::unique_ptr<Source> open_x11(const SourceRequest& request) {
  const X11CaptureSpec spec = parse_x11_capture_spec(request.input);
  return live_capture_source(
      request, [&] { return std::make_unique<X11Capture>(spec, request.stop); }, spec.fps);
}

}  // namespace nelf::drivers
