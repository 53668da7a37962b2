#pragma once
// The text a GLSL stage is compiled from, assembled from the embedded shader files: the same at run
// time (core/gl/objects.cpp) and at build time, where every program variant the compositor uses is
// written out and validated by glslangValidator (cmake/write_shader_variants.cpp).
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/embedded.hpp"

namespace nelf::gl {

class ShaderTextError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Shader `name` from `files`: its `#version` line, then `defines` (e.g. "#define NELF_SUBSAMPLES 2\n"),
// then the rest of the file, each `#include "other.glsl"` line replaced by that file (GL drivers
// implement no include directive). Throws ShaderTextError for a missing file or an include cycle.
std::string shader_text(const std::vector<embedded::File>& files, std::string_view name, std::string_view defines);

}  // namespace nelf::gl
