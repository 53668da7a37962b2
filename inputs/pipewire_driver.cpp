// The pipewire driver: `pipewire:` — the screen or window the user chooses in the desktop's
// ScreenCast portal — and `pipewire:node=ID|NAME`, a PipeWire video node (a game's screen-cast
// stream), as a stereo source (inputs/pipewire_capture, inputs/screencast_portal, inputs/live_capture.hpp).
#include <memory>

#include "inputs/live_capture.hpp"
#include "inputs/pipewire_capture.hpp"
#include "inputs/source.hpp"

namespace nelf::drivers {

bool accepts_pipewire(const SourceRequest& request) { return is_pipewire_capture_spec(request.input); }

std::unique_ptr<Source> open_pipewire(const SourceRequest& request) {
  const PipeWireCaptureSpec spec = parse_pipewire_capture_spec(request.input);
  return live_capture_source(
      request, [&] { return std::make_unique<PipeWireCapture>(spec, request.input, request.stop); }, spec.fps);
}

}  // namespace nelf::drivers
