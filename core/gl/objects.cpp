#include "core/gl/objects.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "core/embedded.hpp"
#include "core/gl/egl_context.hpp"
#include "core/gl/shader_text.hpp"

namespace nelf::gl {

namespace {

Shader compile(GLenum stage, std::string_view name, std::string_view defines) {
  std::string text;
  try {
    text = shader_text(embedded::nelf_embedded_shaders(), name, defines);
  } catch (const ShaderTextError& e) {
    throw GlError(e.what());
  }
  Shader shader(glCreateShader(stage));
  const char* text_pointer = text.c_str();
  const GLint length = static_cast<GLint>(text.size());
  glShaderSource(shader.id(), 1, &text_pointer, &length);
  glCompileShader(shader.id());
  GLint ok = 0;
  glGetShaderiv(shader.id(), GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint log_length = 0;
    glGetShaderiv(shader.id(), GL_INFO_LOG_LENGTH, &log_length);
    std::string log(static_cast<std::size_t>(std::max(log_length, 1)), '\0');
    glGetShaderInfoLog(shader.id(), log_length, nullptr, log.data());
    throw GlError(fmt::format("shader {} does not compile: {}", name, log.c_str()));
  }
  return shader;
}

}  // namespace

void check_error(std::string_view what) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) throw GlError(fmt::format("OpenGL error 0x{:x} in {}", error, what));
}

namespace {
void set_linear_clamp(GLuint id) {
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}
}  // namespace

Texture make_texture_2d(GLenum internal_format, int width, int height) {
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  Texture texture(id);
  glTextureStorage2D(id, 1, internal_format, width, height);
  set_linear_clamp(id);
  check_error(fmt::format("creating a {}x{} texture", width, height));
  return texture;
}

Texture make_bgra8_texture_2d(int width, int height) {
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  Texture texture(id);
  // Mesa picks the storage from the first specification's format when the internal format is
  // unsized (GL_RGBA with GL_BGRA data: B8G8R8A8); sized GL_RGBA8, or glTextureStorage2D, gives
  // R8G8B8A8. Mutable storage, then, with one level.
  GLint bound = 0;
  glGetIntegerv(GL_TEXTURE_BINDING_2D, &bound);
  glBindTexture(GL_TEXTURE_2D, id);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA, width, height, 0, GL_BGRA, GL_UNSIGNED_BYTE, nullptr);
  glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(bound));
  glTextureParameteri(id, GL_TEXTURE_MAX_LEVEL, 0);
  set_linear_clamp(id);
  check_error(fmt::format("creating a {}x{} BGRA texture", width, height));
  return texture;
}

Framebuffer make_framebuffer(const Texture& colour) {
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  Framebuffer framebuffer(id);
  glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0, colour.id(), 0);
  const GLenum status = glCheckNamedFramebufferStatus(id, GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) throw GlError(fmt::format("framebuffer incomplete (0x{:x})", status));
  return framebuffer;
}

VertexArray make_vertex_array() {
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  return VertexArray(id);
}

Buffer make_uniform_buffer(std::size_t bytes) {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  Buffer buffer(id);
  glNamedBufferStorage(id, static_cast<GLsizeiptr>(bytes), nullptr, GL_DYNAMIC_STORAGE_BIT);
  check_error("creating a uniform buffer");
  return buffer;
}

Sampler make_linear_clamp_sampler() {
  GLuint id = 0;
  glCreateSamplers(1, &id);
  glSamplerParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glSamplerParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glSamplerParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return Sampler(id);
}

Program make_program(std::string_view vertex_name, std::string_view fragment_name, std::string_view defines) {
  const Shader vertex = compile(GL_VERTEX_SHADER, vertex_name, defines);
  const Shader fragment = compile(GL_FRAGMENT_SHADER, fragment_name, defines);
  Program program(glCreateProgram());
  glAttachShader(program.id(), vertex.id());
  glAttachShader(program.id(), fragment.id());
  glLinkProgram(program.id());
  GLint ok = 0;
  glGetProgramiv(program.id(), GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint log_length = 0;
    glGetProgramiv(program.id(), GL_INFO_LOG_LENGTH, &log_length);
    std::string log(static_cast<std::size_t>(std::max(log_length, 1)), '\0');
    glGetProgramInfoLog(program.id(), log_length, nullptr, log.data());
    throw GlError(fmt::format("shaders {} + {} do not link: {}", vertex_name, fragment_name, log.c_str()));
  }
  glDetachShader(program.id(), vertex.id());
  glDetachShader(program.id(), fragment.id());
  return program;
}

}  // namespace nelf::gl
