// How a shader's text is assembled (core/gl/shader_text.hpp) and which programs the compositor
// compiles (compositor/gl/shader_programs.hpp): what the build validates is what runs.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "compositor/gl/shader_programs.hpp"
#include "core/gl/shader_text.hpp"

namespace nelf {
namespace {

const std::vector<embedded::File> files = {
    {"main.frag", "#version 450 core\n// main\n#include \"a.glsl\"\nvoid main() {}\n"},
    {"a.glsl", "// a\n#include \"b.glsl\"\nfloat a() { return b(); }"},
    {"b.glsl", "float b() { return 1.0; }\n"},
    {"cycle.frag", "#version 450 core\n#include \"cycle.glsl\"\n"},
    {"cycle.glsl", "#include \"cycle.glsl\"\n"},
    {"missing.frag", "#version 450 core\n#include \"nowhere.glsl\"\n"},
};

TEST(ShaderText, VersionFirstThenDefinesThenTheFileWithItsIncludesSpliced) {
  EXPECT_EQ(gl::shader_text(files, "main.frag", "#define X 1\n"),
            "#version 450 core\n#define X 1\n// main\n// a\nfloat b() { return 1.0; }\nfloat a() { return b(); }\n"
            "void main() {}\n");
}

TEST(ShaderText, AMissingFileOrAnIncludeCycleIsAnError) {
  EXPECT_THROW(gl::shader_text(files, "absent.frag", ""), gl::ShaderTextError);
  EXPECT_THROW(gl::shader_text(files, "missing.frag", ""), gl::ShaderTextError);
  EXPECT_THROW(gl::shader_text(files, "cycle.frag", ""), gl::ShaderTextError);
}

TEST(ShaderPrograms, EveryProgramTheCompositorCanAskForIsAValidatedVariant) {
  const auto variants = shaders::every_program_variant();
  std::set<std::string> names, programs;
  for (const auto& v : variants) {
    EXPECT_TRUE(names.insert(v.name).second) << "duplicate name " << v.name;
    programs.insert(std::string(v.source.vertex) + "|" + std::string(v.source.fragment) + "|" + v.source.defines);
  }
  for (shaders::ProgramKind kind : shaders::every_program_kind)
    for (int subsamples : shaders::subsample_counts) {
      const auto s = shaders::program_source(kind, subsamples);
      EXPECT_TRUE(programs.count(std::string(s.vertex) + "|" + std::string(s.fragment) + "|" + s.defines))
          << "kind " << static_cast<int>(kind) << " with " << subsamples << " sub-samples is not validated";
    }
  EXPECT_THROW(shaders::program_source(shaders::ProgramKind::elemental, 3), std::invalid_argument);
}

}  // namespace
}  // namespace nelf
