#include "core/module_path.hpp"

#include <cstdlib>
#include <vector>

namespace nelf {

namespace fs = std::filesystem;

fs::path find_module(const char* variable, const char* file_name, const char* installed, const char* built) {
  if (const char* explicit_path = std::getenv(variable); explicit_path && *explicit_path) return explicit_path;
  std::vector<fs::path> paths;
  std::error_code ec;
  const fs::path executable = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) paths.push_back(executable.parent_path().parent_path() / "lib" / "nelf" / file_name);
  paths.emplace_back(installed);
  paths.emplace_back(built);
  for (const fs::path& p : paths)
    if (fs::exists(p, ec)) return p;
  return paths.front();
}

}  // namespace nelf
