#include "core/gl/egl_context.hpp"

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <fmt/format.h>

#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <string_view>
#include <vector>

namespace nelf::gl {

namespace {

std::string egl_error_name(EGLint code) {
  switch (code) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default:
      return fmt::format("EGL error 0x{:x}", code);
  }
}

bool has_extension(const char* list, std::string_view name) {
  if (!list) return false;
  std::string_view all(list);
  std::size_t pos = 0;
  while ((pos = all.find(name, pos)) != std::string_view::npos) {
    const bool starts = pos == 0 || all[pos - 1] == ' ';
    const bool ends = pos + name.size() == all.size() || all[pos + name.size()] == ' ';
    if (starts && ends) return true;
    pos += name.size();
  }
  return false;
}

// EGL hands out one EGLDisplay per device and eglTerminate ends it for every user in the process,
// so initialisations are counted and only the last owner terminates.
std::mutex display_mutex;
std::map<EGLDisplay, int> display_users;

bool initialize_display(EGLDisplay display) {
  std::lock_guard lock(display_mutex);
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) return false;
  ++display_users[display];
  return true;
}

void release_display(EGLDisplay display) {
  std::lock_guard lock(display_mutex);
  const auto it = display_users.find(display);
  if (it == display_users.end()) return;
  if (--it->second == 0) {
    display_users.erase(it);
    eglTerminate(display);
  }
}

// A display plus a desktop GL 4.5 core context on it, or the reason it failed.
struct Attempt {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  std::string failure;
};

Attempt try_display(EGLDisplay display) {
  Attempt a;
  if (display == EGL_NO_DISPLAY) {
    a.failure = "no display (" + egl_error_name(eglGetError()) + ")";
    return a;
  }
  if (!initialize_display(display)) {
    a.failure = "eglInitialize failed (" + egl_error_name(eglGetError()) + ")";
    return a;
  }
  const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
  const auto fail = [&](std::string why) {
    release_display(display);
    a.failure = std::move(why);
    return a;
  };
  if (!has_extension(extensions, "EGL_KHR_no_config_context") ||
      !has_extension(extensions, "EGL_KHR_surfaceless_context"))
    return fail("lacks EGL_KHR_no_config_context or EGL_KHR_surfaceless_context");
  if (!eglBindAPI(EGL_OPENGL_API)) return fail("no desktop OpenGL API (" + egl_error_name(eglGetError()) + ")");
  const EGLint attributes[] = {
      EGL_CONTEXT_MAJOR_VERSION,           4,       EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
  if (context == EGL_NO_CONTEXT)
    return fail("cannot create an OpenGL 4.5 core context (" + egl_error_name(eglGetError()) + ")");
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    eglDestroyContext(display, context);
    return fail("eglMakeCurrent without surface failed (" + egl_error_name(eglGetError()) + ")");
  }
  a.display = display;
  a.context = context;
  return a;
}

std::vector<EGLDeviceEXT> query_devices() {
  std::vector<EGLDeviceEXT> devices;
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!has_extension(client, "EGL_EXT_device_enumeration") && !has_extension(client, "EGL_EXT_device_base"))
    return devices;
  if (!has_extension(client, "EGL_EXT_platform_device")) return devices;
  EGLint count = 0;
  if (!eglQueryDevicesEXT(0, nullptr, &count) || count <= 0) return devices;
  devices.resize(static_cast<std::size_t>(count));
  if (!eglQueryDevicesEXT(count, devices.data(), &count)) return {};
  devices.resize(static_cast<std::size_t>(count));
  return devices;
}

bool device_is_software(EGLDeviceEXT device) {
  return has_extension(eglQueryDeviceStringEXT(device, EGL_EXTENSIONS), "EGL_MESA_device_software");
}

std::string device_name(EGLDeviceEXT device) {
  if (device_is_software(device)) return "software";
  if (has_extension(eglQueryDeviceStringEXT(device, EGL_EXTENSIONS), "EGL_EXT_device_drm")) {
    if (const char* file = eglQueryDeviceStringEXT(device, EGL_DRM_DEVICE_FILE_EXT)) return file;
  }
  return "hardware";
}

GlError gpu_not_listed(int gpu, std::size_t devices) {
  return GlError(fmt::format("GPU {} requested but EGL lists {} device(s) (indices 0..{})", gpu, devices,
                             static_cast<int>(devices) - 1));
}

}  // namespace

std::optional<int> requested_gpu(const ContextOptions& options) {
  if (options.gpu) {
    if (*options.gpu < 0) throw GlError(fmt::format("--gpu must be >= 0, got {}", *options.gpu));
    return options.gpu;
  }
  const char* env = std::getenv("NELF_GPU");
  if (!env || !*env) return std::nullopt;
  char* end = nullptr;
  const long value = std::strtol(env, &end, 10);
  if (*end != '\0' || value < 0 || value > 1000)
    throw GlError(fmt::format("NELF_GPU must be a device index >= 0, got '{}'", env));
  return static_cast<int>(value);
}

void check_requested_gpu(const ContextOptions& options) {
  const std::optional<int> gpu = requested_gpu(options);
  if (!gpu) return;
  const std::size_t devices = query_devices().size();
  if (static_cast<std::size_t>(*gpu) >= devices) throw gpu_not_listed(*gpu, devices);
}

EglContext::EglContext(const ContextOptions& options) {
  const std::optional<int> gpu = requested_gpu(options);
  const std::vector<EGLDeviceEXT> devices = query_devices();
  std::vector<std::string> tried;
  Attempt chosen;

  const auto try_device = [&](std::size_t index) {
    const EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[index], nullptr);
    Attempt a = try_display(display);
    const std::string label =
        fmt::format("EGL device {} of {} ({})", index, devices.size(), device_name(devices[index]));
    if (a.context == EGL_NO_CONTEXT) {
      tried.push_back(label + ": " + a.failure);
      return false;
    }
    chosen = a;
    device_ = label;
    software_ = device_is_software(devices[index]);
    return true;
  };

  if (gpu) {
    // An explicit choice is honoured or refused, never silently replaced by another device.
    if (static_cast<std::size_t>(*gpu) >= devices.size()) throw gpu_not_listed(*gpu, devices.size());
    if (!try_device(static_cast<std::size_t>(*gpu)))
      throw GlError(fmt::format("GPU {} requested but unusable: {}", *gpu, tried.back()));
  } else {
    // Hardware devices first, then software ones.
    for (int pass = 0; pass < 2 && chosen.context == EGL_NO_CONTEXT; ++pass)
      for (std::size_t i = 0; i < devices.size() && chosen.context == EGL_NO_CONTEXT; ++i)
        if (device_is_software(devices[i]) == (pass == 1)) try_device(i);
    if (devices.empty()) tried.push_back("EGL_EXT_platform_device: no devices listed");
    if (chosen.context == EGL_NO_CONTEXT) {
      const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
      if (has_extension(client, "EGL_MESA_platform_surfaceless")) {
        Attempt a = try_display(eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr));
        if (a.context != EGL_NO_CONTEXT) {
          chosen = a;
          device_ = "surfaceless platform";
        } else {
          tried.push_back("surfaceless platform: " + a.failure);
        }
      } else {
        tried.push_back("surfaceless platform: EGL_MESA_platform_surfaceless not supported");
      }
    }
  }
  if (chosen.context == EGL_NO_CONTEXT) {
    std::string all;
    for (const auto& t : tried) all += (all.empty() ? "" : "; ") + t;
    throw GlError("no usable headless OpenGL 4.5 core context (tried " + all +
                  "); install Mesa's EGL/llvmpipe (libegl-mesa0, libgl1-mesa-dri) or a GPU driver");
  }
  display_ = chosen.display;
  context_ = chosen.context;
  if (const auto* r = glGetString(GL_RENDERER)) renderer_ = reinterpret_cast<const char*>(r);
  if (device_ == "surfaceless platform") software_ = is_software_renderer(renderer_);
}

EglContext::~EglContext() {
  if (display_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_) eglDestroyContext(display_, context_);
    release_display(display_);
  }
}

void EglContext::make_current() const {
  if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
    throw GlError("eglMakeCurrent failed (" + egl_error_name(eglGetError()) + ")");
}

bool is_software_renderer(const std::string& renderer) {
  for (const char* name : {"llvmpipe", "softpipe", "swrast", "SWR"})
    if (renderer.find(name) != std::string::npos) return true;
  return false;
}

}  // namespace nelf::gl
