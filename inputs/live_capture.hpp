#pragma once
// A live picture read as it changes — an X11 window (inputs/x11_capture), a PipeWire node
// (inputs/pipewire_capture) — and the stereo source made of one (inputs/live_capture_source.cpp):
// split by the same layout rules as a file of its size (aspect, the frame-packed sizes, --layout).
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "inputs/source.hpp"
#include "inputs/view_bytes.hpp"

namespace nelf {

// One read of the picture: tightly packed 8-bit pixels in `order` (an X server's BGRX as it keeps
// them, or RGBA), row 0 the top, alpha 255 or unset.
struct CapturedImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;
  ByteOrder order = ByteOrder::rgba;
  std::chrono::steady_clock::time_point captured_at;  // when the read finished (CLOCK_MONOTONIC)
};

class LiveCapture {
 public:
  virtual ~LiveCapture() = default;
  // The picture now (the first frame), without waiting for a change.
  virtual CapturedImage read() = 0;
  // Waits up to `wait` for the picture to change, then reads it; nothing when it did not change in
  // that time or the capture ended (closed()).
  virtual std::optional<CapturedImage> read_when_changed(std::chrono::milliseconds wait) = 0;
  // What was captured is gone (the window closed, the node was removed): the stream ends.
  virtual bool closed() const = 0;
  // "window 0x1e00002 \"Doom 3\"", "PipeWire node 42 \"gamescope\"".
  virtual const std::string& description() const = 0;
};

// The stereo source of the capture `open` makes of request.input; `frame_rate` is the stream's
// nominal rate. A layout a single picture cannot hold (alt, pair) is refused (UserError, status 2)
// before anything is opened. A picture resized while it is read is scaled to its first size, so
// that the stream keeps one geometry, as a recording must.
std::unique_ptr<Source> live_capture_source(const SourceRequest& request,
                                            const std::function<std::unique_ptr<LiveCapture>()>& open,
                                            double frame_rate);

}  // namespace nelf
