#pragma once
// Move-only RAII owners for OpenGL object names (GL 4.5 direct state access). Each deletes its
// object on destruction; the context must be current then (the compositor owns both and destroys
// the objects first).
#include <epoxy/gl.h>

#include <string_view>
#include <utility>

namespace nelf::gl {

template <class Traits>
class Object {
 public:
  Object() = default;
  explicit Object(GLuint id) : id_(id) {}
  ~Object() { reset(); }
  Object(const Object&) = delete;
  Object& operator=(const Object&) = delete;
  Object(Object&& other) noexcept : id_(std::exchange(other.id_, 0)) {}
  Object& operator=(Object&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, 0);
    }
    return *this;
  }
  GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() {
    if (id_) Traits::destroy(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

struct TextureTraits {
  static void destroy(GLuint id) { glDeleteTextures(1, &id); }
};
struct FramebufferTraits {
  static void destroy(GLuint id) { glDeleteFramebuffers(1, &id); }
};
struct BufferTraits {
  static void destroy(GLuint id) { glDeleteBuffers(1, &id); }
};
struct VertexArrayTraits {
  static void destroy(GLuint id) { glDeleteVertexArrays(1, &id); }
};
struct ProgramTraits {
  static void destroy(GLuint id) { glDeleteProgram(id); }
};
struct SamplerTraits {
  static void destroy(GLuint id) { glDeleteSamplers(1, &id); }
};
struct ShaderTraits {
  static void destroy(GLuint id) { glDeleteShader(id); }
};

using Texture = Object<TextureTraits>;
using Framebuffer = Object<FramebufferTraits>;
using Buffer = Object<BufferTraits>;
using VertexArray = Object<VertexArrayTraits>;
using Program = Object<ProgramTraits>;
using Shader = Object<ShaderTraits>;
using Sampler = Object<SamplerTraits>;

// A 2D texture with immutable storage of `internal_format` (e.g. GL_RGBA16F), linear filtering,
// clamped to the edge.
Texture make_texture_2d(GLenum internal_format, int width, int height);
// As make_texture_2d with 8-bit RGBA, but kept in BGRA byte order (as Mesa stores it; what X11 and
// DRM framebuffers hold), for a frame that goes to the screen: uploading BGRA bytes into it and
// blitting it 1:1 to a window are then copies on llvmpipe (0.7 ms each for 1280x1470) instead of
// swizzling shader passes (4 and 5 ms). Drivers that store it otherwise convert, as before.
Texture make_bgra8_texture_2d(int width, int height);
// A framebuffer with `colour` as its only colour attachment; throws GlError when incomplete.
Framebuffer make_framebuffer(const Texture& colour);
VertexArray make_vertex_array();
// A buffer of `bytes` for uniform data, rewritten with glNamedBufferSubData (dynamic storage).
Buffer make_uniform_buffer(std::size_t bytes);
// Bilinear, no mipmaps, clamped to the edge: how every view and intermediate texture is read.
Sampler make_linear_clamp_sampler();
// Compiles and links the embedded shaders `vertex_name` + `fragment_name` (shaders/*.vert|frag);
// `defines` (e.g. "#define X\n") goes right after each shader's #version line and `#include`
// lines are spliced in (core/gl/shader_text.hpp). Throws GlError with
// the info log when that fails.
Program make_program(std::string_view vertex_name, std::string_view fragment_name, std::string_view defines = {});

// Throws GlError naming `what` when glGetError reports an error.
void check_error(std::string_view what);

}  // namespace nelf::gl
