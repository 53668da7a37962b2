#pragma once
// What the interposer's files share (nelf_glx_stereo.cpp, both_eyes.cpp, swap_control.cpp): the real
// GLX and GL entry points under the interposed ones, and what each context keeps for the window it
// draws into.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/glx.h>

#include <cstdint>
#include <mutex>
#include <unordered_map>

#include "inputs/glx_interposer/nelf_link.hpp"

namespace nelf::glx_interposer {

using DlsymFn = void* (*)(void*, const char*) noexcept;
// The real dlsym, found by version since dlsym itself is interposed (glibc 2.34 moved it).
DlsymFn real_dlsym();
// libGL as the game would get it; its own handle, so that a game that loads libGL privately
// (RTLD_LOCAL, as GLFW and SDL2 do) is served from the same library.
void* libgl();
// One line on the game's standard error.
void say(const char* line);

template <typename Fn>
Fn real_glx(const char* name) {
  void* gl = libgl();
  return gl ? reinterpret_cast<Fn>(real_dlsym()(gl, name)) : nullptr;
}

using GetProcFn = __GLXextFuncPtr (*)(const GLubyte*);
GetProcFn real_get_proc();

// A GL entry point of the current context's driver (core and extension functions alike).
template <typename Fn>
Fn real_gl(const char* name) {
  const GetProcFn get = real_get_proc();
  return get ? reinterpret_cast<Fn>(get(reinterpret_cast<const GLubyte*>(name))) : nullptr;
}

#define NELF_REAL_GLX(name) static const auto real_##name = real_glx<decltype(&::name)>(#name)
#define NELF_REAL_GL(name) static const auto real_##name = real_gl<decltype(&::name)>(#name)

inline bool is_right(GLenum buffer) {
  return buffer == GL_BACK_RIGHT || buffer == GL_FRONT_RIGHT || buffer == GL_RIGHT;
}
inline bool is_both(GLenum buffer) { return buffer == GL_BACK || buffer == GL_FRONT || buffer == GL_FRONT_AND_BACK; }

// What one context keeps for the window it draws into.
struct Eyes {
  bool active = false;    // the game drew into a right buffer: each eye has its own framebuffer
  bool unusable = false;  // the framebuffers could not be made: the game runs in mono
  Display* display = nullptr;
  GLXDrawable drawable = 0;
  GLuint fbo[2] = {0, 0}, color[2] = {0, 0}, depth[2] = {0, 0};
  int width = 0, height = 0;
  GLenum draw_buffer = GL_BACK, read_buffer = GL_BACK;  // as the game set them on "framebuffer 0"
  GLuint game_draw_fbo = 0, game_read_fbo = 0;          // the game's own framebuffer objects, 0: ours
  bool compiling_list = false;  // between the game's glNewList and glEndList: drawing is recorded
  GLuint immediate_list = 0;    // glBegin … glEnd into both eyes: recorded here, then called twice
  bool recording_immediate = false;
  std::uint64_t swaps = 0;
  std::int64_t returned_ns = 0;  // when the last swap returned to the game (0: none yet)
  bool window_unpaced = false;   // the driver's swap interval set to 0: nelf's refreshes pace the game
  NelfLink link;
};

// Every context's Eyes, under g_mutex; the calling thread's current one.
extern std::mutex g_mutex;
std::unordered_map<GLXContext, Eyes>& contexts();
extern thread_local Eyes* t_current;

// Swap control (swap_control.cpp): the interval the game asked for (1 until it asks, GLX's
// default), the driver's own for the game's window, and a wait to a CLOCK_MONOTONIC time.
int swap_interval();
void driver_swap_interval(Display* dpy, GLXDrawable drawable, int interval);
void sleep_until_ns(std::int64_t t);

}  // namespace nelf::glx_interposer

// Drawing into both back buffers (GL_BACK on a stereo framebuffer) draws into both eyes: each of
// these calls, as (name, parameters, arguments), is defined in both_eyes.cpp to be made into each
// eye's framebuffer, and answered for by name in nelf_glx_stereo.cpp's interposed().
#define NELF_INTO_EYES_CALLS(X)                                                                                     \
  X(glClear, (GLbitfield mask), (mask))                                                                             \
  X(glClearBufferfv, (GLenum buffer, GLint drawbuffer, const GLfloat* value), (buffer, drawbuffer, value))          \
  X(glClearBufferiv, (GLenum buffer, GLint drawbuffer, const GLint* value), (buffer, drawbuffer, value))            \
  X(glClearBufferuiv, (GLenum buffer, GLint drawbuffer, const GLuint* value), (buffer, drawbuffer, value))          \
  X(glClearBufferfi, (GLenum buffer, GLint drawbuffer, GLfloat depth, GLint stencil),                               \
    (buffer, drawbuffer, depth, stencil))                                                                           \
  X(glDrawArrays, (GLenum mode, GLint first, GLsizei count), (mode, first, count))                                  \
  X(glDrawElements, (GLenum mode, GLsizei count, GLenum type, const void* indices), (mode, count, type, indices))   \
  X(glDrawRangeElements, (GLenum mode, GLuint start, GLuint end, GLsizei count, GLenum type, const void* indices),  \
    (mode, start, end, count, type, indices))                                                                       \
  X(glDrawArraysInstanced, (GLenum mode, GLint first, GLsizei count, GLsizei instances),                            \
    (mode, first, count, instances))                                                                                \
  X(glDrawElementsInstanced, (GLenum mode, GLsizei count, GLenum type, const void* indices, GLsizei instances),     \
    (mode, count, type, indices, instances))                                                                        \
  X(glDrawElementsBaseVertex, (GLenum mode, GLsizei count, GLenum type, const void* indices, GLint base),           \
    (mode, count, type, indices, base))                                                                             \
  X(glDrawRangeElementsBaseVertex,                                                                                  \
    (GLenum mode, GLuint start, GLuint end, GLsizei count, GLenum type, const void* indices, GLint base),           \
    (mode, start, end, count, type, indices, base))                                                                 \
  X(glDrawElementsInstancedBaseVertex,                                                                              \
    (GLenum mode, GLsizei count, GLenum type, const void* indices, GLsizei instances, GLint base),                  \
    (mode, count, type, indices, instances, base))                                                                  \
  X(glMultiDrawArrays, (GLenum mode, const GLint* first, const GLsizei* count, GLsizei n), (mode, first, count, n)) \
  X(glMultiDrawElements, (GLenum mode, const GLsizei* count, GLenum type, const void* const* indices, GLsizei n),   \
    (mode, count, type, indices, n))                                                                                \
  X(glDrawArraysIndirect, (GLenum mode, const void* indirect), (mode, indirect))                                    \
  X(glDrawElementsIndirect, (GLenum mode, GLenum type, const void* indirect), (mode, type, indirect))               \
  X(glBlitFramebuffer,                                                                                              \
    (GLint sx0, GLint sy0, GLint sx1, GLint sy1, GLint dx0, GLint dy0, GLint dx1, GLint dy1, GLbitfield mask,       \
     GLenum filter),                                                                                                \
    (sx0, sy0, sx1, sy1, dx0, dy0, dx1, dy1, mask, filter))                                                         \
  X(glDrawPixels, (GLsizei width, GLsizei height, GLenum format, GLenum type, const void* pixels),                  \
    (width, height, format, type, pixels))                                                                          \
  X(glCopyPixels, (GLint x, GLint y, GLsizei width, GLsizei height, GLenum type), (x, y, width, height, type))      \
  X(glRectf, (GLfloat x1, GLfloat y1, GLfloat x2, GLfloat y2), (x1, y1, x2, y2))                                    \
  X(glRectd, (GLdouble x1, GLdouble y1, GLdouble x2, GLdouble y2), (x1, y1, x2, y2))                                \
  X(glRecti, (GLint x1, GLint y1, GLint x2, GLint y2), (x1, y1, x2, y2))                                            \
  X(glRects, (GLshort x1, GLshort y1, GLshort x2, GLshort y2), (x1, y1, x2, y2))

// Swap control's entry points (swap_control.cpp), which GLX's headers declare only with
// GLX_GLXEXT_PROTOTYPES: nelf_glx_stereo.cpp answers for them by name.
extern "C" {
void glXSwapIntervalEXT(Display* dpy, GLXDrawable drawable, int interval);
int glXSwapIntervalMESA(unsigned int interval);
int glXSwapIntervalSGI(int interval);
int glXGetSwapIntervalMESA();
}
