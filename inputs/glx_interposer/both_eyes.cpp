// Drawing into GL_BACK (both eyes, as a game draws its HUD or clears) is done into each eye: every
// draw call, clear and blit is made twice, once a framebuffer, and immediate mode (glBegin … glEnd)
// is recorded into a display list and that called twice. What a display list, glBitmap or glBegin …
// glEnd change (the current colour, the raster position, matrices) is put back between the two, so
// that the game's state afterwards is that of one call.
#include <optional>

#include "inputs/glx_interposer/interposed_gl.hpp"

namespace nelf::glx_interposer {

namespace {

// Whether drawing now goes into both eyes: GL_BACK (or another name of both) on "framebuffer 0" of
// a context whose eyes have their own framebuffers, and not into a display list being compiled
// (that drawing is recorded, and made into both eyes when the list is called), nor between glBegin
// and glEnd (a list called there is recorded with the vertices).
Eyes* drawing_both_eyes() {
  Eyes* e = t_current;
  return e && e->active && e->game_draw_fbo == 0 && !e->compiling_list && !e->recording_immediate &&
                 is_both(e->draw_buffer)
             ? e
             : nullptr;
}

// The state a display list, glBitmap or immediate mode may change, kept over the first eye's
// drawing and put back before the second: the attribute groups (current colour, raster position,
// enables, …) and the three matrices. Compatibility contexts only, where those calls exist.
class KeptState {
 public:
  KeptState() {
    NELF_REAL_GL(glGetIntegerv);
    NELF_REAL_GL(glGetFloatv);
    NELF_REAL_GL(glPushAttrib);
    GLint depth = 0, most = 0;
    real_glGetIntegerv(GL_ATTRIB_STACK_DEPTH, &depth);
    real_glGetIntegerv(GL_MAX_ATTRIB_STACK_DEPTH, &most);
    pushed_ = depth < most;
    if (pushed_) real_glPushAttrib(GL_ALL_ATTRIB_BITS);
    real_glGetIntegerv(GL_MATRIX_MODE, &mode_);
    real_glGetFloatv(GL_MODELVIEW_MATRIX, matrices_[0]);
    real_glGetFloatv(GL_PROJECTION_MATRIX, matrices_[1]);
    real_glGetFloatv(GL_TEXTURE_MATRIX, matrices_[2]);
  }
  void put_back() const {
    NELF_REAL_GL(glPopAttrib);
    NELF_REAL_GL(glMatrixMode);
    NELF_REAL_GL(glLoadMatrixf);
    if (pushed_) real_glPopAttrib();
    const GLenum modes[3] = {GL_MODELVIEW, GL_PROJECTION, GL_TEXTURE};
    for (int i = 0; i < 3; ++i) {
      real_glMatrixMode(modes[i]);
      real_glLoadMatrixf(matrices_[i]);
    }
    real_glMatrixMode(static_cast<GLenum>(mode_));
  }

 private:
  bool pushed_ = false;
  GLint mode_ = GL_MODELVIEW;
  GLfloat matrices_[3][16] = {};
};

// Makes `draw` into the right eye, then into the left, when drawing goes into both; once otherwise.
// `keep_state`: for calls that change state (display lists, glBitmap, immediate mode).
template <typename Draw>
void into_eyes(Draw draw, bool keep_state = false) {
  NELF_REAL_GL(glBindFramebuffer);
  const Eyes* e = drawing_both_eyes();
  if (!e) return draw();
  std::optional<KeptState> kept;
  if (keep_state) kept.emplace();
  real_glBindFramebuffer(GL_DRAW_FRAMEBUFFER, e->fbo[1]);
  draw();
  real_glBindFramebuffer(GL_DRAW_FRAMEBUFFER, e->fbo[0]);
  if (kept) kept->put_back();
  draw();
}

}  // namespace

}  // namespace nelf::glx_interposer

using namespace nelf::glx_interposer;

extern "C" {

#define NELF_INTO_EYES(name, parameters, arguments)             \
  __attribute__((visibility("default"))) void name parameters { \
    NELF_REAL_GL(name);                                         \
    into_eyes([&] { real_##name arguments; });                  \
  }
NELF_INTO_EYES_CALLS(NELF_INTO_EYES)
#undef NELF_INTO_EYES

// These change state (a list may set the colour or a matrix; glBitmap moves the raster position):
// it is put back between the eyes.
__attribute__((visibility("default"))) void glCallList(GLuint list) {
  NELF_REAL_GL(glCallList);
  into_eyes([&] { real_glCallList(list); }, true);
}
__attribute__((visibility("default"))) void glCallLists(GLsizei n, GLenum type, const void* lists) {
  NELF_REAL_GL(glCallLists);
  into_eyes([&] { real_glCallLists(n, type, lists); }, true);
}
__attribute__((visibility("default"))) void glBitmap(GLsizei width, GLsizei height, GLfloat x, GLfloat y,
                                                     GLfloat move_x, GLfloat move_y, const GLubyte* bitmap) {
  NELF_REAL_GL(glBitmap);
  into_eyes([&] { real_glBitmap(width, height, x, y, move_x, move_y, bitmap); }, true);
}

// Drawing recorded into the game's own display list is made into both eyes when the list is called.
__attribute__((visibility("default"))) void glNewList(GLuint list, GLenum mode) {
  NELF_REAL_GL(glNewList);
  if (Eyes* e = t_current) e->compiling_list = true;
  real_glNewList(list, mode);
}
__attribute__((visibility("default"))) void glEndList() {
  NELF_REAL_GL(glEndList);
  if (Eyes* e = t_current) e->compiling_list = false;
  real_glEndList();
}

// Immediate mode into both eyes: the vertices between glBegin and glEnd are recorded into a list of
// the interposer's, which is then called into each eye.
__attribute__((visibility("default"))) void glBegin(GLenum mode) {
  NELF_REAL_GL(glBegin);
  NELF_REAL_GL(glGenLists);
  NELF_REAL_GL(glNewList);
  if (Eyes* e = drawing_both_eyes()) {
    if (!e->immediate_list) e->immediate_list = real_glGenLists(1);
    if (e->immediate_list) {
      real_glNewList(e->immediate_list, GL_COMPILE);
      e->recording_immediate = true;
    }
  }
  real_glBegin(mode);
}
__attribute__((visibility("default"))) void glEnd() {
  NELF_REAL_GL(glEnd);
  NELF_REAL_GL(glEndList);
  NELF_REAL_GL(glCallList);
  real_glEnd();
  Eyes* e = t_current;
  if (!e || !e->recording_immediate) return;
  e->recording_immediate = false;
  real_glEndList();
  into_eyes([&] { real_glCallList(e->immediate_list); }, true);
}

}  // extern "C"
