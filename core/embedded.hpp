#pragma once
// Files embedded into the binary at build time (cmake/Embed.cmake): shaders and built-in profiles.
#include <optional>
#include <string_view>
#include <vector>

namespace nelf::embedded {

struct File {
  std::string_view name;  // file name without directory, e.g. "hmz-t1.toml"
  std::string_view contents;
};

const std::vector<File>& nelf_embedded_shaders();
const std::vector<File>& nelf_embedded_profiles();

// The contents of the embedded file called `name` in `files`, if any.
inline std::optional<std::string_view> find(const std::vector<File>& files, std::string_view name) {
  for (const auto& f : files)
    if (f.name == name) return f.contents;
  return std::nullopt;
}

}  // namespace nelf::embedded
