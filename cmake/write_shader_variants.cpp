// Build step (CMakeLists.txt, nelf_validate_shaders): writes every program the compositor compiles
// (compositor/gl/shader_programs.cpp) as the text GL is given (core/gl/shader_text.cpp), so that
// glslangValidator checks each define combination and each linked pair, not only the files as
// they are.
//   nelf_write_shader_variants OUT_DIR
// writes OUT_DIR/NAME.vert and OUT_DIR/NAME.frag per program and OUT_DIR/programs.txt, one NAME a line.
#include <filesystem>
#include <fstream>
#include <iostream>

#include "compositor/gl/shader_programs.hpp"
#include "core/gl/shader_text.hpp"

namespace {

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out.flush()) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: nelf_write_shader_variants OUT_DIR\n";
    return 2;
  }
  try {
    const std::filesystem::path out = argv[1];
    std::filesystem::create_directories(out);
    const auto& files = nelf::embedded::nelf_embedded_shaders();
    std::string names;
    for (const auto& variant : nelf::shaders::every_program_variant()) {
      write_file(out / (variant.name + ".vert"),
                 nelf::gl::shader_text(files, variant.source.vertex, variant.source.defines));
      write_file(out / (variant.name + ".frag"),
                 nelf::gl::shader_text(files, variant.source.fragment, variant.source.defines));
      names += variant.name + "\n";
    }
    write_file(out / "programs.txt", names);
  } catch (const std::exception& e) {
    std::cerr << "nelf_write_shader_variants: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
