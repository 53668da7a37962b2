// nelf-glx-stereo.so: loaded into a game by `nelf run` (LD_PRELOAD), it gives OpenGL games that ask
// for quad-buffer stereo what Mesa never offers: stereo visuals and FBConfigs, and a back buffer per
// eye. Everything the game draws into GL_BACK_LEFT / GL_BACK_RIGHT goes into two framebuffer objects
// of the window's size; at each swap both eyes are read into shared memory for nelf's `glx-stereo:`
// source (inputs/glx_stereo_protocol.hpp), with their depth buffers when nelf asks for them, the left eye is copied
// into the window so that the game's own window still shows its picture, and the real swap follows. A game that never
// draws into a right buffer is left as it is (its window is captured instead).
//
// Games reach GLX and GL in three ways, all covered: by linking libGL (the symbols below win over
// libGL's through LD_PRELOAD), through glXGetProcAddress(ARB) (GLFW, SDL2, libepoxy), and through
// dlsym on a libGL handle they opened themselves (GLFW and SDL2 load libGL.so.1 that way, libepoxy
// for GL 1.x): dlsym is interposed too and answers with these functions for the names they cover.
//
// The game's view of the default framebuffer is kept: binding framebuffer 0 binds the current eye's
// object, and the bindings, draw and read buffers it queries are what it set. Drawing with GL_BACK
// goes into both eyes (both_eyes.cpp); swap control is offered against nelf's refreshes
// (swap_control.cpp).
#include <dlfcn.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "inputs/glx_interposer/interposed_gl.hpp"
#include "inputs/glx_interposer/nelf_link.hpp"
#include "inputs/glx_stereo_protocol.hpp"

namespace nelf::glx_interposer {

DlsymFn real_dlsym() {
  static const DlsymFn fn = [] {
    void* f = dlvsym(RTLD_NEXT, "dlsym", "GLIBC_2.34");
    if (!f) f = dlvsym(RTLD_NEXT, "dlsym", "GLIBC_2.2.5");
    return reinterpret_cast<DlsymFn>(f);
  }();
  return fn;
}

void* libgl() {
  static void* handle = dlopen("libGL.so.1", RTLD_LAZY | RTLD_LOCAL);
  return handle;
}

void say(const char* line) { std::fprintf(stderr, "nelf-glx-stereo: %s\n", line); }

GetProcFn real_get_proc() {
  static const GetProcFn fn = real_glx<GetProcFn>("glXGetProcAddressARB");
  return fn;
}

std::mutex g_mutex;
std::unordered_map<GLXContext, Eyes>& contexts() {
  static std::unordered_map<GLXContext, Eyes> map;
  return map;
}
thread_local Eyes* t_current = nullptr;

}  // namespace nelf::glx_interposer

using namespace nelf::glx_interposer;

namespace {

namespace protocol = nelf::glx_stereo;

// A game that draws one picture (glXSwapBuffers): the swaps waited for before it is taken as one,
// then its window's picture at each swap, read from the back buffer as a quad-buffer game's eyes
// are (nelf splits it by its layout). One window at a time: the one shown is the first that
// swaps; the game's next window takes its place when the context drawing the shown one is
// destroyed (toolkits open a new display connection, whose window may have the same XID) or the
// shown one has not swapped for half a second. Swaps come from the game's drawing thread.
int g_mono_swaps = 0;
std::int64_t g_first_swap_ns = 0;
struct Picture {
  NelfLink link;
  GLXContext context = nullptr;
  GLXDrawable drawable = 0;
  int width = 0, height = 0;
  std::uint64_t swaps = 0;
  std::int64_t last_swap_ns = 0;
  std::int64_t returned_ns = 0;  // when the last swap of its window returned to the game (0: none yet)
  bool window_unpaced = false;   // the driver's swap interval set to 0: nelf's refreshes pace the game
};
Picture g_picture;

// This thread's context is now `context`, drawing into `drawable` (both make-current calls).
void made_current(Display* display, GLXDrawable drawable, GLXContext context) {
  std::lock_guard lock(g_mutex);
  t_current = context ? &contexts()[context] : nullptr;
  if (t_current) {
    t_current->display = display;
    t_current->drawable = drawable;
  }
}

int eye_of(GLenum buffer) { return is_right(buffer) ? 1 : 0; }

void bind_draw(const Eyes& e) {
  NELF_REAL_GL(glBindFramebuffer);
  real_glBindFramebuffer(GL_DRAW_FRAMEBUFFER, e.game_draw_fbo ? e.game_draw_fbo : e.fbo[eye_of(e.draw_buffer)]);
}
void bind_read(const Eyes& e) {
  NELF_REAL_GL(glBindFramebuffer);
  real_glBindFramebuffer(GL_READ_FRAMEBUFFER, e.game_read_fbo ? e.game_read_fbo : e.fbo[eye_of(e.read_buffer)]);
}

bool drawable_size(const Eyes& e, int& width, int& height) {
  NELF_REAL_GLX(glXQueryDrawable);
  unsigned w = 0, h = 0;
  real_glXQueryDrawable(e.display, e.drawable, GLX_WIDTH, &w);
  real_glXQueryDrawable(e.display, e.drawable, GLX_HEIGHT, &h);
  width = static_cast<int>(w);
  height = static_cast<int>(h);
  return width > 0 && height > 0;
}

// (Re)allocates both eyes' colour and depth-stencil storage at the window's size.
bool allocate(Eyes& e, int width, int height) {
  NELF_REAL_GL(glGetIntegerv);
  NELF_REAL_GL(glBindRenderbuffer);
  NELF_REAL_GL(glRenderbufferStorage);
  NELF_REAL_GL(glBindFramebuffer);
  NELF_REAL_GL(glFramebufferRenderbuffer);
  NELF_REAL_GL(glCheckFramebufferStatus);
  GLint renderbuffer = 0, draw = 0;
  real_glGetIntegerv(GL_RENDERBUFFER_BINDING, &renderbuffer);
  real_glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw);
  bool complete = true;
  for (int i = 0; i < 2; ++i) {
    real_glBindRenderbuffer(GL_RENDERBUFFER, e.color[i]);
    real_glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    real_glBindRenderbuffer(GL_RENDERBUFFER, e.depth[i]);
    real_glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, width, height);
    real_glBindFramebuffer(GL_DRAW_FRAMEBUFFER, e.fbo[i]);
    real_glFramebufferRenderbuffer(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, e.color[i]);
    real_glFramebufferRenderbuffer(GL_DRAW_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, e.depth[i]);
    complete = complete && real_glCheckFramebufferStatus(GL_DRAW_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  }
  real_glBindRenderbuffer(GL_RENDERBUFFER, static_cast<GLuint>(renderbuffer));
  real_glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(draw));
  e.width = width;
  e.height = height;
  return complete;
}

// The game drew into a right buffer for the first time: from now on each eye has its own
// framebuffer, the left one starting with what the game drew into the window's back buffer.
void activate(Eyes& e) {
  NELF_REAL_GL(glGenFramebuffers);
  NELF_REAL_GL(glGenRenderbuffers);
  NELF_REAL_GL(glBindFramebuffer);
  NELF_REAL_GL(glBlitFramebuffer);
  NELF_REAL_GL(glReadBuffer);
  NELF_REAL_GL(glDrawBuffer);
  NELF_REAL_GL(glIsEnabled);
  NELF_REAL_GL(glDisable);
  NELF_REAL_GL(glEnable);
  int width = 0, height = 0;
  if (!real_glGenFramebuffers || !real_glBlitFramebuffer || !drawable_size(e, width, height)) {
    say("the game's OpenGL has no framebuffer objects: it runs in mono, and nelf shows its window");
    e.unusable = true;
    return;
  }
  real_glGenFramebuffers(2, e.fbo);
  real_glGenRenderbuffers(2, e.color);
  real_glGenRenderbuffers(2, e.depth);
  if (!allocate(e, width, height)) {
    say("cannot make a framebuffer per eye: the game runs in mono, and nelf shows its window");
    e.unusable = true;
    real_glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return;
  }
  const bool scissor = real_glIsEnabled(GL_SCISSOR_TEST);
  real_glDisable(GL_SCISSOR_TEST);
  real_glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  real_glReadBuffer(GL_BACK);
  real_glBindFramebuffer(GL_DRAW_FRAMEBUFFER, e.fbo[0]);
  real_glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  if (scissor) real_glEnable(GL_SCISSOR_TEST);
  for (int i = 0; i < 2; ++i) {
    real_glBindFramebuffer(GL_FRAMEBUFFER, e.fbo[i]);
    real_glDrawBuffer(GL_COLOR_ATTACHMENT0);
    real_glReadBuffer(GL_COLOR_ATTACHMENT0);
  }
  e.active = true;
  bind_draw(e);
  bind_read(e);
}

// glReadPixels into tightly packed client memory while it lives, whatever the game set (a pixel
// pack buffer, row length, alignment, skips): the game's settings come back after.
class TightPacking {
 public:
  TightPacking() {
    NELF_REAL_GL(glGetIntegerv);
    real_glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &pack_buffer_);
    for (std::size_t i = 0; i < kStore.size(); ++i) real_glGetIntegerv(kStore[i], &saved_[i]);
    set(0, {4, 0, 0, 0});
  }
  ~TightPacking() { set(static_cast<GLuint>(pack_buffer_), saved_); }
  TightPacking(const TightPacking&) = delete;
  TightPacking& operator=(const TightPacking&) = delete;

 private:
  static constexpr std::array<GLenum, 4> kStore{GL_PACK_ALIGNMENT, GL_PACK_ROW_LENGTH, GL_PACK_SKIP_ROWS,
                                                GL_PACK_SKIP_PIXELS};
  static void set(GLuint buffer, const std::array<GLint, 4>& values) {
    NELF_REAL_GL(glBindBuffer);
    NELF_REAL_GL(glPixelStorei);
    if (real_glBindBuffer) real_glBindBuffer(GL_PIXEL_PACK_BUFFER, buffer);
    for (std::size_t i = 0; i < kStore.size(); ++i) real_glPixelStorei(kStore[i], values[i]);
  }
  GLint pack_buffer_ = 0;
  std::array<GLint, 4> saved_{};
};

// Both eyes into the next shared slot, rows bottom-up as GL reads them, and their depth buffers
// when nelf wants them.
void send_eyes(Eyes& e, std::int64_t swapped_ns) {
  NELF_REAL_GL(glBindFramebuffer);
  NELF_REAL_GL(glReadPixels);
  if (!e.link.connected() &&
      !e.link.connect(true, static_cast<std::uint32_t>(e.width), static_cast<std::uint32_t>(e.height)))
    return;
  unsigned char* slot = e.link.begin_slot(e.swaps);
  if (!slot) return;
  const TightPacking packing;
  const std::size_t eye_bytes =
      protocol::eye_bytes(static_cast<std::uint32_t>(e.width), static_cast<std::uint32_t>(e.height));
  for (int i = 0; i < 2; ++i) {
    real_glBindFramebuffer(GL_READ_FRAMEBUFFER, e.fbo[i]);
    real_glReadPixels(0, 0, e.width, e.height, GL_RGBA, GL_UNSIGNED_BYTE, slot + protocol::kSlotHeader + i * eye_bytes);
  }
  e.link.read_messages();
  const bool depth = e.link.depth_wanted();
  for (int i = 0; depth && i < 2; ++i) {
    real_glBindFramebuffer(GL_READ_FRAMEBUFFER, e.fbo[i]);
    real_glReadPixels(
        0, 0, e.width, e.height, GL_DEPTH_COMPONENT, GL_FLOAT,
        slot + protocol::depth_offset(static_cast<std::uint32_t>(e.width), static_cast<std::uint32_t>(e.height), i));
  }
  reinterpret_cast<protocol::SlotHeader*>(slot)->depth = depth ? 1 : 0;
  reinterpret_cast<protocol::SlotHeader*>(slot)->bgrx = 0;
  e.link.end_slot(slot, e.swaps, swapped_ns);
}

// The window's picture into the next shared slot (where a left eye goes), rows bottom-up, read
// from the back buffer the swap is about to show. Read as BGRA, the order the window's pixels are
// kept in (X visuals): Mesa's software OpenGL then copies the rows, where RGBA took it a pass that
// swaps every pixel's bytes, time the frame waits to be shown (docs/PERFORMANCE.md). nelf reorders
// the block means it makes of them.
void send_picture(Picture& p, std::int64_t swapped_ns) {
  NELF_REAL_GL(glGetIntegerv);
  NELF_REAL_GL(glBindFramebuffer);
  NELF_REAL_GL(glReadBuffer);
  NELF_REAL_GL(glReadPixels);
  unsigned char* slot = p.link.begin_slot(p.swaps);
  if (!slot) return;
  GLint read_framebuffer = 0, read_buffer = GL_BACK;
  if (real_glBindFramebuffer) real_glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_framebuffer);
  real_glGetIntegerv(GL_READ_BUFFER, &read_buffer);
  {
    const TightPacking packing;
    if (real_glBindFramebuffer) real_glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    real_glReadBuffer(GL_BACK);
    real_glReadPixels(0, 0, p.width, p.height, GL_BGRA, GL_UNSIGNED_BYTE, slot + protocol::kSlotHeader);
  }
  if (read_framebuffer == 0) real_glReadBuffer(static_cast<GLenum>(read_buffer));
  if (real_glBindFramebuffer) real_glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(read_framebuffer));
  if (read_framebuffer != 0) real_glReadBuffer(static_cast<GLenum>(read_buffer));
  p.link.read_messages();
  reinterpret_cast<protocol::SlotHeader*>(slot)->depth = 0;
  reinterpret_cast<protocol::SlotHeader*>(slot)->bgrx = 1;
  p.link.end_slot(slot, p.swaps, swapped_ns);
}

// A swap of a game that draws one picture: the picture to nelf, and with a swap interval the swap
// returns in time for nelf's refresh, as for a quad-buffer game.
void swap_picture(Display* dpy, GLXDrawable drawable) {
  NELF_REAL_GLX(glXSwapBuffers);
  NELF_REAL_GLX(glXQueryDrawable);
  NELF_REAL_GLX(glXGetCurrentContext);
  Picture& p = g_picture;
  const std::int64_t swapped_ns = monotonic_ns();
  if (p.link.connected() && drawable != p.drawable && swapped_ns - p.last_swap_ns >= 500'000'000)
    p.link.close();  // the window shown stopped swapping: the game's next window takes its place
  const bool shown = !p.link.connected() || drawable == p.drawable;
  if (shown) {
    unsigned width = 0, height = 0;
    real_glXQueryDrawable(dpy, drawable, GLX_WIDTH, &width);
    real_glXQueryDrawable(dpy, drawable, GLX_HEIGHT, &height);
    // A resized window: nelf is told the new size on a new link.
    if (p.link.connected() && (static_cast<int>(width) != p.width || static_cast<int>(height) != p.height))
      p.link.close();
    if (!p.link.connected() && width > 0 && height > 0 && p.link.connect(false, width, height)) {
      p.context = real_glXGetCurrentContext();
      p.drawable = drawable;
      p.width = static_cast<int>(width);
      p.height = static_cast<int>(height);
      p.window_unpaced = false;
    }
    if (p.link.connected()) {
      send_picture(p, swapped_ns);
      p.last_swap_ns = swapped_ns;
    }
  }
  const int interval = swap_interval();
  const bool paced = shown && interval > 0 && p.link.linked_for_frames();
  const std::int64_t game_ns = p.returned_ns != 0 ? swapped_ns - p.returned_ns : 0;  // its last frame's drawing
  if (paced && !p.window_unpaced) {
    driver_swap_interval(dpy, drawable, 0);
    p.window_unpaced = true;
  }
  real_glXSwapBuffers(dpy, drawable);
  if (!shown) return;
  const std::int64_t returns = paced ? p.link.swap_returns_ns(monotonic_ns(), interval, game_ns, p.returned_ns) : 0;
  ++p.swaps;
  if (returns != 0) sleep_until_ns(returns);
  p.returned_ns = monotonic_ns();
}

// The left eye into the window's back buffer: what the game's own window shows.
void show_left_eye(const Eyes& e) {
  NELF_REAL_GL(glBindFramebuffer);
  NELF_REAL_GL(glDrawBuffer);
  NELF_REAL_GL(glBlitFramebuffer);
  NELF_REAL_GL(glIsEnabled);
  NELF_REAL_GL(glDisable);
  NELF_REAL_GL(glEnable);
  const bool scissor = real_glIsEnabled(GL_SCISSOR_TEST);
  real_glDisable(GL_SCISSOR_TEST);
  real_glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  real_glDrawBuffer(GL_BACK);
  real_glBindFramebuffer(GL_READ_FRAMEBUFFER, e.fbo[0]);
  real_glBlitFramebuffer(0, 0, e.width, e.height, 0, 0, e.width, e.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  if (scissor) real_glEnable(GL_SCISSOR_TEST);
}

// glXChooseVisual's list: GLX_STEREO (a flag without a value) removed.
std::vector<int> without_stereo_flag(const int* attributes) {
  std::vector<int> out;
  for (const int* a = attributes; a && *a != None; ++a) {
    const int name = *a;
    if (name == GLX_STEREO) continue;
    out.push_back(name);
    const bool flag = name == GLX_USE_GL || name == GLX_RGBA || name == GLX_DOUBLEBUFFER;
    if (!flag) out.push_back(*++a);
  }
  out.push_back(None);
  return out;
}

// glXChooseFBConfig's list of pairs: the GLX_STEREO pair removed.
std::vector<int> without_stereo_pair(const int* attributes) {
  std::vector<int> out;
  for (const int* a = attributes; a && *a != None; a += 2)
    if (a[0] != GLX_STEREO) out.insert(out.end(), {a[0], a[1]});
  out.push_back(None);
  return out;
}

}  // namespace

extern "C" {

__attribute__((visibility("default"))) XVisualInfo* glXChooseVisual(Display* dpy, int screen, int* attributes) {
  NELF_REAL_GLX(glXChooseVisual);
  std::vector<int> list = without_stereo_flag(attributes);
  return real_glXChooseVisual(dpy, screen, list.data());
}

__attribute__((visibility("default"))) GLXFBConfig* glXChooseFBConfig(Display* dpy, int screen, const int* attributes,
                                                                      int* count) {
  NELF_REAL_GLX(glXChooseFBConfig);
  std::vector<int> list = without_stereo_pair(attributes);
  return real_glXChooseFBConfig(dpy, screen, list.data(), count);
}

// Every double-buffered configuration is a stereo one: the interposer gives it a second back buffer.
__attribute__((visibility("default"))) int glXGetFBConfigAttrib(Display* dpy, GLXFBConfig config, int attribute,
                                                                int* value) {
  NELF_REAL_GLX(glXGetFBConfigAttrib);
  if (attribute != GLX_STEREO) return real_glXGetFBConfigAttrib(dpy, config, attribute, value);
  return real_glXGetFBConfigAttrib(dpy, config, GLX_DOUBLEBUFFER, value);
}

__attribute__((visibility("default"))) int glXGetConfig(Display* dpy, XVisualInfo* visual, int attribute, int* value) {
  NELF_REAL_GLX(glXGetConfig);
  if (attribute != GLX_STEREO) return real_glXGetConfig(dpy, visual, attribute, value);
  return real_glXGetConfig(dpy, visual, GLX_DOUBLEBUFFER, value);
}

__attribute__((visibility("default"))) Bool glXMakeContextCurrent(Display* dpy, GLXDrawable draw, GLXDrawable read,
                                                                  GLXContext context) {
  NELF_REAL_GLX(glXMakeContextCurrent);
  const Bool ok = real_glXMakeContextCurrent(dpy, draw, read, context);
  if (ok) made_current(dpy, draw, context);
  return ok;
}

__attribute__((visibility("default"))) Bool glXMakeCurrent(Display* dpy, GLXDrawable drawable, GLXContext context) {
  NELF_REAL_GLX(glXMakeCurrent);
  const Bool ok = real_glXMakeCurrent(dpy, drawable, context);
  if (ok) made_current(dpy, drawable, context);
  return ok;
}

__attribute__((visibility("default"))) void glXDestroyContext(Display* dpy, GLXContext context) {
  NELF_REAL_GLX(glXDestroyContext);
  {
    std::lock_guard lock(g_mutex);
    auto it = contexts().find(context);
    if (it != contexts().end()) {
      if (t_current == &it->second) t_current = nullptr;
      contexts().erase(it);  // its framebuffers go with the context
    }
    if (g_picture.link.connected() && g_picture.context == context) g_picture.link.close();  // its window closes
  }
  real_glXDestroyContext(dpy, context);
}

__attribute__((visibility("default"))) void glXSwapBuffers(Display* dpy, GLXDrawable drawable) {
  NELF_REAL_GLX(glXSwapBuffers);
  Eyes* e = t_current;
  if (!e || !e->active || e->drawable != drawable) {
    // A game that draws one picture: its picture goes to nelf at each swap. Toolkits swap before
    // the game draws: that waits for 5 swaps and a fifth of a second of them (a quad-buffer game
    // draws both eyes from its first frame).
    // (The picture is read from the current context's drawable: a swap of another is passed on.)
    if (e && !e->active && e->drawable == drawable) {
      const std::int64_t now = monotonic_ns();
      if (g_mono_swaps++ == 0) g_first_swap_ns = now;
      if (g_mono_swaps >= 5 && now - g_first_swap_ns >= 200'000'000) return swap_picture(dpy, drawable);
    }
    real_glXSwapBuffers(dpy, drawable);
    return;
  }
  // A game that drew one picture, then both eyes: nelf is told on a new link, for the eyes.
  if (g_picture.link.connected()) g_picture.link.close();
  const std::int64_t swapped_ns = monotonic_ns();
  send_eyes(*e, swapped_ns);
  show_left_eye(*e);
  const int interval = swap_interval();
  const std::int64_t game_ns = e->returned_ns != 0 ? swapped_ns - e->returned_ns : 0;  // its last frame's drawing
  const bool paced = interval > 0 && e->link.linked_for_frames();
  if (paced && !e->window_unpaced) {
    driver_swap_interval(dpy, drawable, 0);
    e->window_unpaced = true;
  }
  real_glXSwapBuffers(dpy, drawable);
  // With a swap interval the swap returns in time for nelf's refresh, as vsync would
  // (protocol: vsync_returns_ns).
  const std::int64_t returns = paced ? e->link.swap_returns_ns(monotonic_ns(), interval, game_ns, e->returned_ns) : 0;
  ++e->swaps;
  // A resized window: the eyes follow, and nelf is told the new size on a new link.
  int width = 0, height = 0;
  if (drawable_size(*e, width, height) && (width != e->width || height != e->height)) {
    allocate(*e, width, height);
    e->link.close();
  }
  bind_draw(*e);
  bind_read(*e);
  if (returns != 0) sleep_until_ns(returns);
  e->returned_ns = monotonic_ns();
}

__attribute__((visibility("default"))) void glDrawBuffer(GLenum buffer) {
  NELF_REAL_GL(glDrawBuffer);
  Eyes* e = t_current;
  if (e && !e->active && !e->unusable && is_right(buffer) && e->game_draw_fbo == 0) activate(*e);
  if (!e || !e->active || e->game_draw_fbo != 0) return real_glDrawBuffer(buffer);
  e->draw_buffer = buffer;
  bind_draw(*e);
  real_glDrawBuffer(buffer == GL_NONE ? GL_NONE : GL_COLOR_ATTACHMENT0);
}

__attribute__((visibility("default"))) void glDrawBuffers(GLsizei n, const GLenum* buffers) {
  NELF_REAL_GL(glDrawBuffers);
  Eyes* e = t_current;
  if (e && e->game_draw_fbo == 0 && n >= 1) return glDrawBuffer(buffers[0]);  // one eye at a time
  real_glDrawBuffers(n, buffers);
}

__attribute__((visibility("default"))) void glReadBuffer(GLenum buffer) {
  NELF_REAL_GL(glReadBuffer);
  Eyes* e = t_current;
  if (!e || !e->active || e->game_read_fbo != 0) return real_glReadBuffer(buffer);
  e->read_buffer = buffer;
  bind_read(*e);
  real_glReadBuffer(buffer == GL_NONE ? GL_NONE : GL_COLOR_ATTACHMENT0);
}

__attribute__((visibility("default"))) void glBindFramebuffer(GLenum target, GLuint framebuffer) {
  NELF_REAL_GL(glBindFramebuffer);
  Eyes* e = t_current;
  if (e) {
    if (target == GL_FRAMEBUFFER || target == GL_DRAW_FRAMEBUFFER) e->game_draw_fbo = framebuffer;
    if (target == GL_FRAMEBUFFER || target == GL_READ_FRAMEBUFFER) e->game_read_fbo = framebuffer;
  }
  if (!e || !e->active || framebuffer != 0) return real_glBindFramebuffer(target, framebuffer);
  if (target == GL_FRAMEBUFFER || target == GL_DRAW_FRAMEBUFFER) bind_draw(*e);
  if (target == GL_FRAMEBUFFER || target == GL_READ_FRAMEBUFFER) bind_read(*e);
}

__attribute__((visibility("default"))) void glBindFramebufferEXT(GLenum target, GLuint framebuffer) {
  glBindFramebuffer(target, framebuffer);
}

// What the game set, as it would read it from a real stereo framebuffer.
__attribute__((visibility("default"))) void glGetIntegerv(GLenum name, GLint* data) {
  NELF_REAL_GL(glGetIntegerv);
  real_glGetIntegerv(name, data);
  const Eyes* e = t_current;
  if (name == GL_STEREO && e) *data = GL_TRUE;
  if (!e || !e->active) return;
  if (name == GL_DRAW_FRAMEBUFFER_BINDING) *data = static_cast<GLint>(e->game_draw_fbo);
  if (name == GL_READ_FRAMEBUFFER_BINDING) *data = static_cast<GLint>(e->game_read_fbo);
  if ((name == GL_DRAW_BUFFER || name == GL_DRAW_BUFFER0) && e->game_draw_fbo == 0)
    *data = static_cast<GLint>(e->draw_buffer);
  if (name == GL_READ_BUFFER && e->game_read_fbo == 0) *data = static_cast<GLint>(e->read_buffer);
}

__attribute__((visibility("default"))) void glGetBooleanv(GLenum name, GLboolean* data) {
  NELF_REAL_GL(glGetBooleanv);
  real_glGetBooleanv(name, data);
  if (name == GL_STEREO && t_current) *data = GL_TRUE;
}

__GLXextFuncPtr glXGetProcAddressARB(const GLubyte* name);

__attribute__((visibility("default"))) void (*glXGetProcAddress(const GLubyte* name))() {
  return glXGetProcAddressARB(name);
}

__attribute__((visibility("default"))) void* dlsym(void* handle, const char* name) noexcept;

}  // extern "C"

namespace {

// The functions above by name: what glXGetProcAddress and dlsym answer with instead of libGL's.
void* interposed(const char* name) {
  struct Entry {
    const char* name;
    void* function;
  };
  static const Entry table[] = {
      {"glXChooseVisual", reinterpret_cast<void*>(&glXChooseVisual)},
      {"glXChooseFBConfig", reinterpret_cast<void*>(&glXChooseFBConfig)},
      {"glXGetFBConfigAttrib", reinterpret_cast<void*>(&glXGetFBConfigAttrib)},
      {"glXGetConfig", reinterpret_cast<void*>(&glXGetConfig)},
      {"glXMakeCurrent", reinterpret_cast<void*>(&glXMakeCurrent)},
      {"glXMakeContextCurrent", reinterpret_cast<void*>(&glXMakeContextCurrent)},
      {"glXDestroyContext", reinterpret_cast<void*>(&glXDestroyContext)},
      {"glXSwapBuffers", reinterpret_cast<void*>(&glXSwapBuffers)},
      {"glXSwapIntervalEXT", reinterpret_cast<void*>(&glXSwapIntervalEXT)},
      {"glXSwapIntervalMESA", reinterpret_cast<void*>(&glXSwapIntervalMESA)},
      {"glXSwapIntervalSGI", reinterpret_cast<void*>(&glXSwapIntervalSGI)},
      {"glXGetSwapIntervalMESA", reinterpret_cast<void*>(&glXGetSwapIntervalMESA)},
      {"glXQueryDrawable", reinterpret_cast<void*>(&glXQueryDrawable)},
      {"glXQueryExtensionsString", reinterpret_cast<void*>(&glXQueryExtensionsString)},
      {"glXGetProcAddress", reinterpret_cast<void*>(&glXGetProcAddress)},
      {"glXGetProcAddressARB", reinterpret_cast<void*>(&glXGetProcAddressARB)},
      {"glDrawBuffer", reinterpret_cast<void*>(&glDrawBuffer)},
      {"glDrawBuffers", reinterpret_cast<void*>(&glDrawBuffers)},
      {"glDrawBuffersARB", reinterpret_cast<void*>(&glDrawBuffers)},
      {"glReadBuffer", reinterpret_cast<void*>(&glReadBuffer)},
      {"glBindFramebuffer", reinterpret_cast<void*>(&glBindFramebuffer)},
      {"glBindFramebufferEXT", reinterpret_cast<void*>(&glBindFramebufferEXT)},
      {"glGetIntegerv", reinterpret_cast<void*>(&glGetIntegerv)},
      {"glGetBooleanv", reinterpret_cast<void*>(&glGetBooleanv)},
      {"glDrawArraysEXT", reinterpret_cast<void*>(&glDrawArrays)},
      {"glDrawRangeElementsEXT", reinterpret_cast<void*>(&glDrawRangeElements)},
      {"glDrawArraysInstancedARB", reinterpret_cast<void*>(&glDrawArraysInstanced)},
      {"glDrawArraysInstancedEXT", reinterpret_cast<void*>(&glDrawArraysInstanced)},
      {"glDrawElementsInstancedARB", reinterpret_cast<void*>(&glDrawElementsInstanced)},
      {"glDrawElementsInstancedEXT", reinterpret_cast<void*>(&glDrawElementsInstanced)},
      {"glMultiDrawArraysEXT", reinterpret_cast<void*>(&glMultiDrawArrays)},
      {"glMultiDrawElementsEXT", reinterpret_cast<void*>(&glMultiDrawElements)},
      {"glBlitFramebufferEXT", reinterpret_cast<void*>(&glBlitFramebuffer)},
      {"glCallList", reinterpret_cast<void*>(&glCallList)},
      {"glCallLists", reinterpret_cast<void*>(&glCallLists)},
      {"glBitmap", reinterpret_cast<void*>(&glBitmap)},
      {"glNewList", reinterpret_cast<void*>(&glNewList)},
      {"glEndList", reinterpret_cast<void*>(&glEndList)},
      {"glBegin", reinterpret_cast<void*>(&glBegin)},
      {"glEnd", reinterpret_cast<void*>(&glEnd)},
  };
  // clang-format off
  static const Entry into_eyes_table[] = {
#define NELF_ENTRY(name, parameters, arguments) {#name, reinterpret_cast<void*>(&name)},
      NELF_INTO_EYES_CALLS(NELF_ENTRY)
#undef NELF_ENTRY
  };
  // clang-format on
  if (!name || name[0] != 'g' || name[1] != 'l') return nullptr;
  for (const std::span<const Entry> entries : {std::span<const Entry>(table), std::span<const Entry>(into_eyes_table)})
    for (const Entry& entry : entries)
      if (std::strcmp(entry.name, name) == 0) return entry.function;
  return nullptr;
}

}  // namespace

extern "C" {

__attribute__((visibility("default"))) __GLXextFuncPtr glXGetProcAddressARB(const GLubyte* name) {
  if (void* ours = interposed(reinterpret_cast<const char*>(name))) return reinterpret_cast<__GLXextFuncPtr>(ours);
  const GetProcFn real = real_get_proc();
  return real ? real(name) : nullptr;
}

// For RTLD_NEXT glibc finds the caller from the return address: the lookups that are not for these
// functions end in a tail call (a jump, built with -foptimize-sibling-calls), so that the caller is
// the game's code, not this library.
__attribute__((visibility("default"))) void* dlsym(void* handle, const char* name) noexcept {
  if (void* ours = interposed(name); ours && real_dlsym()(handle, name)) return ours;
  return real_dlsym()(handle, name);
}

}  // extern "C"
