#pragma once
// The table of functions nelf-oiio.so (module.cpp) hands to nelf (core/image_library.cpp).
// Both are built together from this header; `abi` and `size` catch a module left over from
// another build. The functions throw std::runtime_error with a one-line message.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/image_library.hpp"

namespace nelf::image_library {

struct ModuleApi {
  static constexpr std::uint32_t kAbi = 2;  // bump when a signature or the table changes
  std::uint32_t abi = kAbi;
  std::size_t size = sizeof(ModuleApi);
  Pixels (*read_file)(const std::string& path, const std::string& format, const DecodeLimits& limits) = nullptr;
  Pixels (*decode)(std::span<const std::byte> encoded, const std::string& format, const std::string& name,
                   const DecodeLimits& limits) = nullptr;
  bool (*has_writer)(const std::string& format_or_file_name) = nullptr;
  std::optional<std::vector<unsigned char>> (*encode)(const Picture& picture, const EncodeOptions& options,
                                                      const std::string& path) = nullptr;
  std::optional<TextBox> (*text_size)(const std::string& text, int size, const std::string& font) = nullptr;
  void (*render_text)(const Canvas& canvas, int x, int y, const std::string& text, int size, const std::string& font,
                      std::span<const float> colour, AlignX align_x, AlignY align_y, int shadow) = nullptr;
};

// The module's one exported symbol.
#define NELF_IMAGE_LIBRARY_ENTRY "nelf_image_library_module"
extern "C" const ModuleApi* nelf_image_library_module();

}  // namespace nelf::image_library
