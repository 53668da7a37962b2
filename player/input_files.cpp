#include "player/input_files.hpp"

#include <fmt/format.h>
#include <sys/stat.h>

#include <system_error>

#include "core/user_error.hpp"
#include "inputs/synthetic_source.hpp"

namespace nelf {
namespace {

namespace fs = std::filesystem;

// The local file an input name refers to, or empty when it is none: FFmpeg reads `file:NAME` as
// NAME; other protocols (`pipe:`, URLs) and stdin cannot be written over.
std::string local_file_name(const std::string& name) {
  if (name.empty() || name == "-" || is_synthetic_spec(name)) return {};
  if (name.rfind("file:", 0) == 0) return name.substr(5);
  if (name.find("://") != std::string::npos || name.rfind("pipe:", 0) == 0) return {};
  return name;
}

}  // namespace

void InputFiles::add(const std::string& path, std::string role) {
  const std::string file = local_file_name(path);
  if (file.empty()) return;
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) return;
  std::error_code ec;
  fs::path resolved = fs::canonical(file, ec);
  if (ec) resolved.clear();
  inputs_.push_back({path, std::move(role), std::move(resolved), st.st_dev, st.st_ino});
}

void InputFiles::refuse_as_output(const std::string& output) const {
  const std::string file = local_file_name(output);
  if (file.empty() || inputs_.empty()) return;
  std::error_code ec;
  const fs::path resolved = fs::weakly_canonical(file, ec);
  struct stat st {};
  const bool exists = ::stat(file.c_str(), &st) == 0;
  for (const Input& input : inputs_) {
    const bool same_path = !ec && !input.resolved.empty() && resolved == input.resolved;
    const bool same_file = exists && st.st_dev == input.device && st.st_ino == input.inode;
    if (!same_path && !same_file) continue;
    const std::string named = input.shown == output ? std::string() : fmt::format(" {}", input.shown);
    throw UserError(fmt::format("{}: the output is the same file as {}{}; choose another output name (-y never "
                                "replaces an input)",
                                output, input.role, named),
                    2);
  }
}

}  // namespace nelf
