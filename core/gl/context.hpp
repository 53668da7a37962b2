#pragma once
// What the GL compositor needs from an OpenGL 4.5 core context, whoever created it: the headless
// EGL context (gl/egl_context), a GLFW window's context, or an EGL context on a KMS/GBM surface.
// Implementations own the context; GL objects created under it must die before it does.
#include <string>

namespace nelf::gl {

class Context {
 public:
  virtual ~Context() = default;
  // Makes the context current on the calling thread. Throws GlError when that fails.
  virtual void make_current() const = 0;
  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)" or "NVIDIA H100/PCIe/SSE2".
  virtual const std::string& renderer() const = 0;
  // True on a software rasteriser (llvmpipe, softpipe, swrast).
  virtual bool is_software() const = 0;
};

// True when a GL_RENDERER string names a software rasteriser.
bool is_software_renderer(const std::string& renderer);

}  // namespace nelf::gl
