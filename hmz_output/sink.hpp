#pragma once
// What every output of nelf is, live or file (DESIGN.md §7): something that takes packed frames,
// says what it is, at what rate it shows them, and when it is done. How a frame is handed over
// stays with the kind, because the two pipelines differ where it matters for speed: a Display
// (hmz_output/display.hpp) owns the GL context and framebuffer that play and calibrate render
// into on their one thread, then present(); a FrameSink (hmz_output/frame_sink.hpp) takes CPU
// PackedFrames on convert's writing thread while another thread holds the GL context and
// composites the next frame into a pooled buffer. A GL target for files would put encoding on the
// GL thread and serialise the two.
#include <string>

namespace nelf {

class Sink {
 public:
  virtual ~Sink() = default;
  // One line for logs and the last line of a conversion: "out.mkv", "raw video to stdout",
  // "window 1280x1470 on :99 (llvmpipe, no vsync)".
  virtual std::string description() const = 0;
  // The rate the output shows frames at; 0 when it is untimed and takes them as fast as they come
  // (a file).
  virtual double refresh_hz() const = 0;
  // Everything handed over is complete and in place: a file is renamed into place; a display has
  // shown each frame as it came and has nothing left to do.
  virtual void finish() {}
};

}  // namespace nelf
