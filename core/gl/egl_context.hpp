#pragma once
// A headless OpenGL 4.5 core context through EGL (DESIGN.md §9): no window, no config, rendering
// goes into framebuffer objects. The same code runs on a real GPU (EGL_EXT_platform_device) and on
// Mesa's llvmpipe (its software device, or EGL_PLATFORM_SURFACELESS_MESA as a fall-back).
#include <optional>
#include <stdexcept>
#include <string>

#include "core/gl/context.hpp"

namespace nelf::gl {

// No usable EGL/OpenGL, or a GL call failed. what() is one line saying what was tried.
class GlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ContextOptions {
  // Index into the EGL device list (`nelf --gpu N`). Unset: the environment variable NELF_GPU,
  // else the first hardware device, else Mesa's software device, else the surfaceless platform.
  std::optional<int> gpu;
};

// Owns an EGLContext on an initialised EGLDisplay (shared with other EglContexts on the same
// device; terminated when the last one goes), current on the creating thread. Not copyable or
// movable: the GL objects created under it refer to it; hold it by (shared) pointer.
class EglContext final : public Context {
 public:
  explicit EglContext(const ContextOptions& options = {});
  ~EglContext() override;
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  // Makes the context current on the calling thread (it already is on the creating thread).
  void make_current() const override;

  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)" or "NVIDIA H100/PCIe/SSE2".
  const std::string& renderer() const override { return renderer_; }
  // How the display was obtained, e.g. "EGL device 1 of 2 (software)" or "surfaceless platform".
  const std::string& device() const { return device_; }
  bool is_software() const override { return software_; }

 private:
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  std::string renderer_;
  std::string device_;
  bool software_ = false;
};

// "gpu" from the options, else NELF_GPU (validated: a non-negative integer), else nothing.
std::optional<int> requested_gpu(const ContextOptions& options);

// Throws the GlError EglContext throws for a requested device (requested_gpu) that EGL does not
// list, without creating a context: for work that may not need GL at all (composite tables from
// the cache), so that a wrong --gpu is reported whether or not GL is started.
void check_requested_gpu(const ContextOptions& options);

}  // namespace nelf::gl
