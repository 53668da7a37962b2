#pragma once
// Where a packed frame is drawn: into a GL framebuffer (a display's packed frame) or into bytes in
// memory (a PackedFrame for a file, a pipe, a test). One value, so that whoever composites the
// frame (compositor/frame_compositor.hpp) takes either, and whoever owns the frame (a display, a
// file sink) only says which.
#include <array>
#include <variant>

#include "core/frames.hpp"

namespace nelf {

// A framebuffer whose colour attachment is `texture`, `size` texels (row 0 the frame's top row):
// the GL compositor renders into the framebuffer, a packed frame made on the CPU (BGRA8, what X11
// and DRM framebuffers hold) is uploaded into the texture.
struct GlPackedTarget {
  unsigned int framebuffer = 0;  // GLuint
  unsigned int texture = 0;      // GLuint
  std::array<int, 2> size{0, 0};
};

// The packed frame's bytes: filled (size, depth, pixels, pts) by whoever composites it. The frame
// keeps its memory between frames when the size stays (a pool of buffers hands the same ones back).
struct PackedTarget {
  std::variant<GlPackedTarget, PackedFrame*> where;

  static PackedTarget gl(unsigned int framebuffer, unsigned int texture, std::array<int, 2> size) {
    return {GlPackedTarget{framebuffer, texture, size}};
  }
  static PackedTarget bytes(PackedFrame& frame) { return {&frame}; }
};

}  // namespace nelf
