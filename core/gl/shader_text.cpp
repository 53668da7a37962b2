#include "core/gl/shader_text.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace nelf::gl {

namespace {

constexpr int max_include_depth = 8;

std::string_view file_text(const std::vector<embedded::File>& files, std::string_view name) {
  const auto source = embedded::find(files, name);
  if (!source) throw ShaderTextError(fmt::format("shader {} is not embedded in this build", name));
  return *source;
}

// `text` with each line `#include "file"` replaced by that file, expanded in turn.
std::string expand_includes(const std::vector<embedded::File>& files, std::string_view text, std::string_view name,
                            int depth) {
  if (depth > max_include_depth)
    throw ShaderTextError(fmt::format("shader {}: includes nest deeper than {} (a cycle?)", name, max_include_depth));
  std::string out;
  out.reserve(text.size());
  std::size_t begin = 0;
  while (begin < text.size()) {
    const std::size_t end = std::min(text.find('\n', begin), text.size());
    const std::string_view line = text.substr(begin, end - begin);
    constexpr std::string_view directive = "#include \"";
    if (line.starts_with(directive) && line.size() > directive.size() + 1 && line.back() == '"') {
      const std::string_view included = line.substr(directive.size(), line.size() - directive.size() - 1);
      out += expand_includes(files, file_text(files, included), included, depth + 1);
      if (out.empty() || out.back() != '\n') out += '\n';
    } else {
      out += line;
      if (end < text.size()) out += '\n';
    }
    begin = end + 1;
  }
  return out;
}

}  // namespace

std::string shader_text(const std::vector<embedded::File>& files, std::string_view name, std::string_view defines) {
  const std::string_view source = file_text(files, name);
  // #version must stay the first line: the defines go right after it.
  const std::size_t first_line_end = std::min(source.find('\n'), source.size());
  std::string text(source.substr(0, first_line_end));
  text += '\n';
  text += defines;
  if (first_line_end < source.size()) text += expand_includes(files, source.substr(first_line_end + 1), name, 1);
  return text;
}

}  // namespace nelf::gl
