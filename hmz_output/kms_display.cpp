#include "hmz_output/kms_display.hpp"

#include <drm_fourcc.h>
#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <gbm.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <set>
#include <string_view>

#include "core/gl/egl_context.hpp"
#include "core/gl/objects.hpp"
#include "hmz_output/kms_modes.hpp"
#include "hmz_output/terminal_keys.hpp"

namespace nelf {
namespace {

// unique_ptr deleters for the C handles of libdrm and GBM.
template <auto free_function>
struct Free {
  template <class T>
  void operator()(T* p) const {
    if (p) free_function(p);
  }
};
using VersionPtr = std::unique_ptr<drmVersion, Free<drmFreeVersion>>;
using ResourcesPtr = std::unique_ptr<drmModeRes, Free<drmModeFreeResources>>;
using ConnectorPtr = std::unique_ptr<drmModeConnector, Free<drmModeFreeConnector>>;
using EncoderPtr = std::unique_ptr<drmModeEncoder, Free<drmModeFreeEncoder>>;
using CrtcPtr = std::unique_ptr<drmModeCrtc, Free<drmModeFreeCrtc>>;
using GbmDevicePtr = std::unique_ptr<gbm_device, Free<gbm_device_destroy>>;
using GbmSurfacePtr = std::unique_ptr<gbm_surface, Free<gbm_surface_destroy>>;

// How long present() waits for the page-flip event before calling the output lost: many frames
// at any refresh the HMD supports.
constexpr int kFlipTimeoutMs = 1000;

std::string errno_text(int error) { return std::strerror(error); }

std::string egl_error() { return fmt::format("EGL error 0x{:x}", eglGetError()); }

bool has_extension(const char* list, std::string_view name) {
  if (!list) return false;
  const std::string_view all(list);
  for (std::size_t pos = all.find(name); pos != std::string_view::npos; pos = all.find(name, pos + 1)) {
    const bool starts = pos == 0 || all[pos - 1] == ' ';
    const bool ends = pos + name.size() == all.size() || all[pos + name.size()] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

class DrmFd {
 public:
  DrmFd() = default;
  explicit DrmFd(int fd) : fd_(fd) {}
  ~DrmFd() {
    if (fd_ >= 0) close(fd_);
  }
  DrmFd(DrmFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  DrmFd& operator=(DrmFd&& other) noexcept {
    if (this != &other) {
      if (fd_ >= 0) close(fd_);
      fd_ = std::exchange(other.fd_, -1);
    }
    return *this;
  }
  int get() const { return fd_; }

 private:
  int fd_ = -1;
};

// The DRM fd, the GBM device on it and the EGL display on that: shared by the display and its GL
// context, since the compositor may hold the context a moment longer than the display. Members are
// destroyed in reverse order: EGL display, GBM device, then the fd.
struct KmsGpu {
  std::string path;
  std::string driver;
  DrmFd fd;
  bool became_master = false;
  GbmDevicePtr gbm;
  EGLDisplay egl = EGL_NO_DISPLAY;

  KmsGpu() = default;
  KmsGpu(const KmsGpu&) = delete;
  KmsGpu& operator=(const KmsGpu&) = delete;
  ~KmsGpu() {
    if (egl != EGL_NO_DISPLAY) {
      eglMakeCurrent(egl, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglTerminate(egl);
    }
    gbm.reset();
    // Another program (a display server, fbcon) may take the device over once we are gone.
    if (became_master) drmDropMaster(fd.get());
  }
};

// The OpenGL 4.5 core context on the GBM surface. Current with the window surface while the
// display lives, surfaceless afterwards (so GL objects can still be deleted).
class KmsContext final : public gl::Context {
 public:
  KmsContext(std::shared_ptr<KmsGpu> gpu, EGLContext context) : gpu_(std::move(gpu)), context_(context) {}
  ~KmsContext() override {
    if (eglGetCurrentContext() == context_) eglMakeCurrent(gpu_->egl, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(gpu_->egl, context_);
  }
  KmsContext(const KmsContext&) = delete;
  KmsContext& operator=(const KmsContext&) = delete;

  void make_current() const override {
    if (!eglMakeCurrent(gpu_->egl, surface_, surface_, context_))
      throw gl::GlError(fmt::format("eglMakeCurrent on the KMS surface failed ({})", egl_error()));
  }
  const std::string& renderer() const override { return renderer_; }
  bool is_software() const override { return gl::is_software_renderer(renderer_); }

  void set_surface(EGLSurface surface) { surface_ = surface; }
  void read_renderer() {
    if (const auto* r = glGetString(GL_RENDERER)) renderer_ = reinterpret_cast<const char*>(r);
  }

 private:
  std::shared_ptr<KmsGpu> gpu_;
  EGLContext context_;
  EGLSurface surface_ = EGL_NO_SURFACE;
  std::string renderer_;
};

// What one card offers, with the ids behind the names kms_modes chooses from.
struct ProbedCard {
  std::shared_ptr<KmsGpu> gpu;
  KmsDevice device;
  std::vector<std::uint32_t> connector_ids;         // parallel to device.connectors
  std::vector<std::vector<drmModeModeInfo>> modes;  // parallel to device.connectors[i].modes
};

KmsMode to_kms_mode(const drmModeModeInfo& m) {
  KmsMode k;
  k.name = std::string(m.name, strnlen(m.name, sizeof m.name));
  k.clock_khz = static_cast<int>(m.clock);
  k.hdisplay = m.hdisplay;
  k.htotal = m.htotal;
  k.vdisplay = m.vdisplay;
  k.vtotal = m.vtotal;
  k.vrefresh = static_cast<int>(m.vrefresh);
  k.flags = m.flags;
  k.type = m.type;
  return k;
}

// Opens `path` and reads what it offers; throws KmsError with the reason it cannot be used.
ProbedCard probe_card(const std::string& path, bool from_environment) {
  const int raw = open(path.c_str(), O_RDWR | O_CLOEXEC | O_NOCTTY);
  if (raw < 0) throw KmsError(kms_open_error(path, errno, from_environment));
  ProbedCard card;
  card.gpu = std::make_shared<KmsGpu>();
  card.gpu->path = path;
  card.gpu->fd = DrmFd(raw);
  const int fd = raw;
  const std::string named = from_environment ? "NELF_DRM_DEVICE=" + path : path;
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISCHR(st.st_mode))
    throw KmsError(
        fmt::format("{} is not a DRM device (not a character device); point it at a card node such as "
                    "/dev/dri/card0",
                    named));
  const VersionPtr version(drmGetVersion(fd));
  if (!version)
    throw KmsError(
        fmt::format("{} is not a DRM device (DRM_IOCTL_VERSION: {}); point it at a card node such as "
                    "/dev/dri/card0",
                    named, errno_text(errno)));
  card.gpu->driver = std::string(version->name, static_cast<std::size_t>(std::max(0, version->name_len)));
  card.device.path = path;
  card.device.driver = card.gpu->driver;
  if (drmSetClientCap(fd, DRM_CLIENT_CAP_STEREO_3D, 1) != 0)
    throw KmsError(
        fmt::format("{} ({}) refuses DRM_CLIENT_CAP_STEREO_3D ({}): this kernel cannot send HDMI 3D; "
                    "use a kernel from 3.13 on",
                    path, card.gpu->driver, errno_text(errno)));
  // The legacy SetCrtc/PageFlip path below needs no universal planes or atomic caps.
  const ResourcesPtr resources(drmModeGetResources(fd));
  if (!resources)
    throw KmsError(
        fmt::format("{} ({}) does not do modesetting ({}): a render-only or compute GPU, or nvidia-drm "
                    "without modeset=1; connect the HMD to a GPU with display outputs",
                    path, card.gpu->driver, errno_text(errno)));
  for (int i = 0; i < resources->count_connectors; ++i) {
    const ConnectorPtr c(drmModeGetConnector(fd, resources->connectors[i]));
    if (!c) continue;
    KmsConnector kc;
    kc.name = kms_connector_name(c->connector_type, c->connector_type_id);
    kc.connected = c->connection == DRM_MODE_CONNECTED;
    std::vector<drmModeModeInfo> infos;
    for (int m = 0; m < c->count_modes; ++m) {
      kc.modes.push_back(to_kms_mode(c->modes[m]));
      infos.push_back(c->modes[m]);
    }
    card.device.connectors.push_back(std::move(kc));
    card.connector_ids.push_back(c->connector_id);
    card.modes.push_back(std::move(infos));
  }
  return card;
}

// (These only read the current routing: drmModeGetConnectorCurrent, no new EDID probe.)
// The CRTC to drive `connector_id` with: the one already driving it, else a free one its encoders
// can use.
std::optional<std::uint32_t> choose_crtc(int fd, const drmModeRes& resources, std::uint32_t connector_id) {
  const ConnectorPtr connector(drmModeGetConnectorCurrent(fd, connector_id));
  if (!connector) return std::nullopt;
  if (connector->encoder_id) {
    const EncoderPtr encoder(drmModeGetEncoder(fd, connector->encoder_id));
    if (encoder && encoder->crtc_id) return encoder->crtc_id;
  }
  std::set<std::uint32_t> busy;  // CRTCs other connectors are shown on
  for (int i = 0; i < resources.count_connectors; ++i) {
    if (resources.connectors[i] == connector_id) continue;
    const ConnectorPtr other(drmModeGetConnectorCurrent(fd, resources.connectors[i]));
    if (!other || !other->encoder_id) continue;
    const EncoderPtr encoder(drmModeGetEncoder(fd, other->encoder_id));
    if (encoder && encoder->crtc_id) busy.insert(encoder->crtc_id);
  }
  for (int e = 0; e < connector->count_encoders; ++e) {
    const EncoderPtr encoder(drmModeGetEncoder(fd, connector->encoders[e]));
    if (!encoder) continue;
    for (int i = 0; i < resources.count_crtcs; ++i)
      if ((encoder->possible_crtcs & (1u << i)) && !busy.count(resources.crtcs[i])) return resources.crtcs[i];
  }
  return std::nullopt;
}

// The connectors `crtc_id` drives now, to give it back to them on exit.
std::vector<std::uint32_t> connectors_on_crtc(int fd, const drmModeRes& resources, std::uint32_t crtc_id) {
  std::vector<std::uint32_t> ids;
  for (int i = 0; i < resources.count_connectors; ++i) {
    const ConnectorPtr c(drmModeGetConnectorCurrent(fd, resources.connectors[i]));
    if (!c || !c->encoder_id) continue;
    const EncoderPtr encoder(drmModeGetEncoder(fd, c->encoder_id));
    if (encoder && encoder->crtc_id == crtc_id) ids.push_back(c->connector_id);
  }
  return ids;
}

// A DRM framebuffer for a GBM buffer, made once and kept as the buffer's user data; GBM calls
// destroy() when the surface frees the buffer.
struct BoFramebuffer {
  int fd;
  std::uint32_t id;
  static void destroy(gbm_bo*, void* data) {
    const std::unique_ptr<BoFramebuffer> owned(static_cast<BoFramebuffer*>(data));
    drmModeRmFB(owned->fd, owned->id);
  }
};

class KmsDisplay final : public Display {
 public:
  KmsDisplay(ProbedCard card, const KmsModeChoice& choice, const DisplayOptions& options);
  ~KmsDisplay() override;
  KmsDisplay(const KmsDisplay&) = delete;
  KmsDisplay& operator=(const KmsDisplay&) = delete;

  std::shared_ptr<gl::Context> context() const override { return context_; }
  GLuint packed_framebuffer() const override { return fbo_.id(); }
  GLuint packed_texture() const override { return texture_.id(); }
  std::array<int, 2> packed_size() const override { return {width_, height_}; }
  void present() override;
  double refresh_hz() const override { return refresh_hz_; }
  bool vsync() const override { return true; }
  std::vector<KeyPress> poll_events() override;
  bool close_requested() const override { return close_requested_; }
  std::string description() const override;

 private:
  int fd() const { return gpu_->fd.get(); }
  std::uint32_t framebuffer_for(gbm_bo* bo);
  // Waits for the pending page flip's event; false after kFlipTimeoutMs without it.
  bool wait_for_flip();
  void init(const DisplayOptions& options);
  // Gives the CRTC back and frees everything in dependency order; safe on a half-built display.
  void teardown() noexcept;
  void restore_crtc() noexcept;

  std::shared_ptr<KmsGpu> gpu_;
  std::shared_ptr<KmsContext> context_;
  std::string connector_name_;
  std::uint32_t connector_id_ = 0;
  std::uint32_t crtc_id_ = 0;
  drmModeModeInfo mode_{};
  int width_ = 0;
  int height_ = 0;
  double refresh_hz_ = 0;
  CrtcPtr saved_crtc_;
  std::vector<std::uint32_t> saved_connectors_;
  GbmSurfacePtr gbm_surface_;
  EGLSurface egl_surface_ = EGL_NO_SURFACE;
  gl::Texture texture_;
  gl::Framebuffer fbo_;
  gbm_bo* shown_bo_ = nullptr;  // locked: on screen now
  bool mode_set_ = false;
  bool flip_pending_ = false;
  bool close_requested_ = false;
  TerminalKeys keys_{STDIN_FILENO};
};

KmsDisplay::KmsDisplay(ProbedCard card, const KmsModeChoice& choice, const DisplayOptions& options)
    : gpu_(std::move(card.gpu)),
      connector_name_(choice.connector_name),
      connector_id_(card.connector_ids[choice.connector_index]),
      mode_(card.modes[choice.connector_index][choice.mode_index]),
      width_(choice.packed_width),
      height_(choice.packed_height),
      refresh_hz_(choice.refresh_hz) {
  try {
    init(options);
  } catch (...) {
    teardown();  // the destructor does not run for a half-built display
    throw;
  }
}

void KmsDisplay::init(const DisplayOptions& options) {
  if (options.packed[0] != width_ || options.packed[1] != height_)
    throw KmsError(fmt::format("{} {} scans out {}x{} frames but the signal {} packs {}x{}", gpu_->path,
                               connector_name_, width_, height_, options.signal.name, options.packed[0],
                               options.packed[1]));
  const int fd = gpu_->fd.get();
  // Reading modes needs no master; setting them does. Once another client (X, a Wayland
  // compositor) is master, drmSetMaster fails.
  if (!drmIsMaster(fd)) {
    if (drmSetMaster(fd) != 0) throw KmsError(kms_master_error(gpu_->path, "become DRM master", errno));
    gpu_->became_master = true;
  }
  const ResourcesPtr resources(drmModeGetResources(fd));
  if (!resources) throw KmsError(fmt::format("{}: cannot read the DRM resources ({})", gpu_->path, errno_text(errno)));
  const auto crtc = choose_crtc(fd, *resources, connector_id_);
  if (!crtc)
    throw KmsError(
        fmt::format("{}: no free display controller (CRTC) can drive {}; disconnect another monitor from "
                    "this GPU",
                    gpu_->path, connector_name_));
  crtc_id_ = *crtc;
  saved_crtc_.reset(drmModeGetCrtc(fd, crtc_id_));
  saved_connectors_ = connectors_on_crtc(fd, *resources, crtc_id_);
  if (saved_connectors_.empty()) saved_connectors_.push_back(connector_id_);

  gpu_->gbm.reset(gbm_create_device(fd));
  if (!gpu_->gbm)
    throw KmsError(
        fmt::format("{} ({}): GBM cannot use this device ({}); install Mesa's GBM (libgbm1) and the "
                    "driver's Mesa backend",
                    gpu_->path, gpu_->driver, errno_text(errno)));
  gbm_surface_.reset(gbm_surface_create(gpu_->gbm.get(), static_cast<std::uint32_t>(width_),
                                        static_cast<std::uint32_t>(height_), GBM_FORMAT_XRGB8888,
                                        GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING));
  if (!gbm_surface_)
    throw KmsError(fmt::format("{} ({}): cannot create a {}x{} XRGB8888 scan-out surface ({})", gpu_->path,
                               gpu_->driver, width_, height_, errno_text(errno)));

  // EGL on the GBM platform with a desktop OpenGL 4.5 core context.
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!has_extension(client, "EGL_EXT_platform_base") ||
      (!has_extension(client, "EGL_KHR_platform_gbm") && !has_extension(client, "EGL_MESA_platform_gbm")))
    throw KmsError("EGL has no GBM platform (EGL_KHR_platform_gbm); install Mesa's EGL (libegl-mesa0)");
  gpu_->egl = eglGetPlatformDisplayEXT(EGL_PLATFORM_GBM_KHR, gpu_->gbm.get(), nullptr);
  if (gpu_->egl == EGL_NO_DISPLAY || !eglInitialize(gpu_->egl, nullptr, nullptr)) {
    gpu_->egl = EGL_NO_DISPLAY;
    throw KmsError(
        fmt::format("{} ({}): no EGL display on its GBM device ({})", gpu_->path, gpu_->driver, egl_error()));
  }
  if (!eglBindAPI(EGL_OPENGL_API))
    throw KmsError(fmt::format("{} ({}): EGL offers no desktop OpenGL ({})", gpu_->path, gpu_->driver, egl_error()));
  const EGLint config_attributes[] = {
      EGL_SURFACE_TYPE,    EGL_WINDOW_BIT, EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
      EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLint count = 0;
  eglChooseConfig(gpu_->egl, config_attributes, nullptr, 0, &count);
  std::vector<EGLConfig> configs(static_cast<std::size_t>(std::max(count, 0)));
  if (count > 0) eglChooseConfig(gpu_->egl, config_attributes, configs.data(), count, &count);
  configs.resize(static_cast<std::size_t>(std::max(count, 0)));
  EGLConfig config = nullptr;
  for (EGLConfig c : configs) {
    EGLint visual = 0;
    if (eglGetConfigAttrib(gpu_->egl, c, EGL_NATIVE_VISUAL_ID, &visual) &&
        static_cast<std::uint32_t>(visual) == GBM_FORMAT_XRGB8888) {
      config = c;
      break;
    }
  }
  if (!config)
    throw KmsError(
        fmt::format("{} ({}): no EGL config renders OpenGL into XRGB8888 GBM surfaces", gpu_->path, gpu_->driver));
  const EGLint context_attributes[] = {
      EGL_CONTEXT_MAJOR_VERSION,           4,       EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  const EGLContext egl_context = eglCreateContext(gpu_->egl, config, EGL_NO_CONTEXT, context_attributes);
  if (egl_context == EGL_NO_CONTEXT)
    throw KmsError(
        fmt::format("{} ({}): the GPU offers no OpenGL 4.5 core context ({}), which nelf's compositor "
                    "needs",
                    gpu_->path, gpu_->driver, egl_error()));
  context_ = std::make_shared<KmsContext>(gpu_, egl_context);
  egl_surface_ = eglCreatePlatformWindowSurfaceEXT(gpu_->egl, config, gbm_surface_.get(), nullptr);
  if (egl_surface_ == EGL_NO_SURFACE)
    throw KmsError(
        fmt::format("{} ({}): cannot create an EGL window surface on GBM ({})", gpu_->path, gpu_->driver, egl_error()));
  context_->set_surface(egl_surface_);
  context_->make_current();
  context_->read_renderer();

  texture_ = gl::make_bgra8_texture_2d(width_, height_);
  fbo_ = gl::make_framebuffer(texture_);
  const GLfloat black[] = {0.f, 0.f, 0.f, 1.f};
  glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, 0, black);
}

KmsDisplay::~KmsDisplay() { teardown(); }

void KmsDisplay::teardown() noexcept {
  if (flip_pending_) wait_for_flip();
  restore_crtc();
  mode_set_ = false;
  if (context_) {
    // The GL objects go while their context is still current with the surface.
    if (egl_surface_ != EGL_NO_SURFACE) {
      try {
        context_->make_current();
      } catch (const gl::GlError&) {
      }
    }
    fbo_.reset();
    texture_.reset();
    context_->set_surface(EGL_NO_SURFACE);
    eglMakeCurrent(gpu_->egl, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  if (shown_bo_) gbm_surface_release_buffer(gbm_surface_.get(), shown_bo_);
  shown_bo_ = nullptr;
  if (egl_surface_ != EGL_NO_SURFACE) eglDestroySurface(gpu_->egl, egl_surface_);
  egl_surface_ = EGL_NO_SURFACE;
  if (context_) {
    // Current again without a surface (EGL_KHR_surfaceless_context, which Mesa's GBM platform
    // has), so that the compositor can still delete its GL objects.
    try {
      context_->make_current();
    } catch (const gl::GlError&) {
    }
  }
  gbm_surface_.reset();  // frees the buffers, whose user data removes their DRM framebuffers
}

void KmsDisplay::restore_crtc() noexcept {
  if (!mode_set_) return;
  if (saved_crtc_ && saved_crtc_->mode_valid) {
    drmModeSetCrtc(fd(), saved_crtc_->crtc_id, saved_crtc_->buffer_id, saved_crtc_->x, saved_crtc_->y,
                   saved_connectors_.data(), static_cast<int>(saved_connectors_.size()), &saved_crtc_->mode);
  } else {
    drmModeSetCrtc(fd(), crtc_id_, 0, 0, 0, nullptr, 0, nullptr);  // it was off: switch it off again
  }
}

std::uint32_t KmsDisplay::framebuffer_for(gbm_bo* bo) {
  if (auto* existing = static_cast<BoFramebuffer*>(gbm_bo_get_user_data(bo))) return existing->id;
  const int planes = gbm_bo_get_plane_count(bo);
  std::uint32_t handles[4] = {}, strides[4] = {}, offsets[4] = {};
  std::uint64_t modifiers[4] = {};
  const std::uint64_t modifier = gbm_bo_get_modifier(bo);
  for (int p = 0; p < planes && p < 4; ++p) {
    handles[p] = gbm_bo_get_handle_for_plane(bo, p).u32;
    strides[p] = gbm_bo_get_stride_for_plane(bo, p);
    offsets[p] = gbm_bo_get_offset(bo, p);
    modifiers[p] = modifier;
  }
  const std::uint32_t w = gbm_bo_get_width(bo), h = gbm_bo_get_height(bo), format = gbm_bo_get_format(bo);
  std::uint32_t id = 0;
  int result = -1;
  if (modifier != DRM_FORMAT_MOD_INVALID)
    result = drmModeAddFB2WithModifiers(fd(), w, h, format, handles, strides, offsets, modifiers, &id,
                                        DRM_MODE_FB_MODIFIERS);
  if (result != 0) result = drmModeAddFB2(fd(), w, h, format, handles, strides, offsets, &id, 0);
  if (result != 0)
    throw std::runtime_error(
        fmt::format("{}: cannot make a {}x{} scan-out framebuffer ({})", gpu_->path, w, h, errno_text(errno)));
  auto owned = std::make_unique<BoFramebuffer>(BoFramebuffer{fd(), id});
  gbm_bo_set_user_data(bo, owned.release(), &BoFramebuffer::destroy);  // GBM owns it from here
  return id;
}

bool KmsDisplay::wait_for_flip() {
  drmEventContext events{};
  events.version = 2;
  events.page_flip_handler = [](int, unsigned, unsigned, unsigned, void* data) {
    static_cast<KmsDisplay*>(data)->flip_pending_ = false;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(kFlipTimeoutMs);
  while (flip_pending_) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) return false;
    pollfd p{fd(), POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(left));
    if (ready < 0 && errno != EINTR) return false;
    if (ready > 0 && drmHandleEvent(fd(), &events) != 0) return false;
  }
  return true;
}

void KmsDisplay::present() {
  // Compositor memory has row 0 = the top row; GL's window row 0 is the bottom: flip.
  glDisable(GL_SCISSOR_TEST);
  glBlitNamedFramebuffer(fbo_.id(), 0, 0, 0, width_, height_, 0, height_, width_, 0, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  if (!eglSwapBuffers(gpu_->egl, egl_surface_))
    throw std::runtime_error(fmt::format("KMS output {}: eglSwapBuffers failed ({})", connector_name_, egl_error()));
  gbm_bo* next = gbm_surface_lock_front_buffer(gbm_surface_.get());
  if (!next) throw std::runtime_error(fmt::format("KMS output {}: no GBM buffer to show", connector_name_));
  try {
    const std::uint32_t fb = framebuffer_for(next);
    if (!mode_set_) {
      if (drmModeSetCrtc(fd(), crtc_id_, fb, 0, 0, &connector_id_, 1, &mode_) != 0) {
        const int error = errno;
        if (error == EACCES || error == EPERM || error == EBUSY)
          throw KmsError(kms_master_error(gpu_->path, "set the 3D mode on " + connector_name_, error));
        throw KmsError(fmt::format("{}: setting {} {} on {} failed ({}); the driver refused the 3D mode", gpu_->path,
                                   mode_.name, "frame packing", connector_name_, errno_text(error)));
      }
      mode_set_ = true;
    } else {
      if (drmModePageFlip(fd(), crtc_id_, fb, DRM_MODE_PAGE_FLIP_EVENT, this) != 0)
        throw std::runtime_error(fmt::format("KMS output {}: page flip failed ({}); the output was lost",
                                             connector_name_, errno_text(errno)));
      flip_pending_ = true;
      if (!wait_for_flip())
        throw std::runtime_error(
            fmt::format("KMS output {}: no vblank within {} ms; the output stopped (HMD off or "
                        "unplugged, or another program took the device)",
                        connector_name_, kFlipTimeoutMs));
    }
  } catch (...) {
    if (!flip_pending_) gbm_surface_release_buffer(gbm_surface_.get(), next);
    close_requested_ = true;
    throw;
  }
  if (shown_bo_) gbm_surface_release_buffer(gbm_surface_.get(), shown_bo_);
  shown_bo_ = next;
}

std::vector<KeyPress> KmsDisplay::poll_events() {
  std::vector<KeyPress> keys = keys_.read_available();
  if (keys_.hung_up()) close_requested_ = true;
  return keys;
}

std::string KmsDisplay::description() const {
  return fmt::format("KMS {} {}x{}@{:.4g}Hz 3D frame packing ({}, {}, {})", connector_name_, width_, height_,
                     refresh_hz_, gpu_->path, gpu_->driver, context_->renderer());
}

}  // namespace

std::string kms_open_error(const std::string& path, int error, bool from_environment) {
  const std::string named = from_environment ? "NELF_DRM_DEVICE=" + path : path;
  switch (error) {
    case ENOENT:
    case ENOTDIR:
      return fmt::format("{}: no such device; {}", named,
                         from_environment ? "set NELF_DRM_DEVICE to a card node such as /dev/dri/card0, or unset it"
                                          : "use --output window");
    case EACCES:
    case EPERM:
      return fmt::format(
          "permission denied opening {}: add your user to the 'video' group (sudo usermod -aG video "
          "$USER, then log in again) or run nelf from a text console (Ctrl+Alt+F3)",
          named);
    case EISDIR:
      return fmt::format("{} is a folder, not a DRM device; point it at a card node such as /dev/dri/card0", named);
    case EBUSY:
      return kms_master_error(path, "open", error);
    default:
      return fmt::format("cannot open {} ({})", named, errno_text(error));
  }
}

std::string kms_master_error(const std::string& path, const std::string& what, int error) {
  if (error == EACCES || error == EPERM || error == EBUSY)
    return fmt::format(
        "cannot {} on {} ({}): a display server (X or Wayland) holds the device; stop the display "
        "server or switch to a text console (Ctrl+Alt+F3) and run nelf there",
        what, path, errno_text(error));
  return fmt::format("cannot {} on {} ({})", what, path, errno_text(error));
}

std::vector<std::filesystem::path> find_drm_cards(const std::filesystem::path& dri_dir) {
  std::vector<std::pair<long, std::filesystem::path>> cards;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dri_dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind("card", 0) != 0 || name.size() == 4) continue;
    const std::string digits = name.substr(4);
    if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) continue;
    cards.emplace_back(std::strtol(digits.c_str(), nullptr, 10), it->path());
  }
  std::sort(cards.begin(), cards.end());
  std::vector<std::filesystem::path> paths;
  for (auto& [number, path] : cards) paths.push_back(std::move(path));
  return paths;
}

std::unique_ptr<Display> open_kms_display(const DisplayOptions& options) {
  std::vector<std::string> paths;
  const char* env = std::getenv("NELF_DRM_DEVICE");
  const bool from_environment = env && *env;
  if (from_environment) {
    paths.push_back(env);
  } else {
    for (const auto& p : find_drm_cards()) paths.push_back(p.string());
    if (paths.empty())
      throw KmsError(
          "no DRM device (no /dev/dri/card*): --output kms needs a GPU with a kernel modesetting driver "
          "on this machine; use --output window");
  }
  std::vector<std::string> failures;
  for (const std::string& path : paths) {
    try {
      ProbedCard card = probe_card(path, from_environment);
      const KmsModeSelection selection = select_kms_mode(card.device, options.connector, options.signal);
      if (!selection) throw KmsError(selection.error);
      return std::make_unique<KmsDisplay>(std::move(card), *selection.choice, options);
    } catch (const KmsError& e) {
      // With one card its reason is the answer; with several, each card says why it is unusable.
      if (paths.size() == 1) throw;
      failures.push_back(path + ": " + e.what());
    }
  }
  std::string all;
  for (const auto& f : failures) all += (all.empty() ? "" : "; ") + f;
  throw KmsError("no usable KMS output: " + all);
}

}  // namespace nelf
