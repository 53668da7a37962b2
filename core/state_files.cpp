#include "core/state_files.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdlib>

#include <fmt/format.h>

#include "core/unix_socket.hpp"

namespace nelf {

namespace fs = std::filesystem;

fs::path xdg_state_home() {
  if (const char* xdg = std::getenv("XDG_STATE_HOME"); xdg && *xdg && fs::path(xdg).is_absolute()) return xdg;
  if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".local" / "state";
  return {};
}

bool replace_file(const fs::path& file, const std::string& text, mode_t mode) {
  std::error_code ec;
  fs::create_directories(file.parent_path(), ec);
  const fs::path temporary = fs::path(file).concat(fmt::format(".{}.tmp", ::getpid()));
  bool written = false;
  {
    const UniqueFd out(::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, mode));
    if (out.get() < 0) return false;
    written = ::write(out.get(), text.data(), text.size()) == static_cast<ssize_t>(text.size());
  }
  if (written) {
    fs::rename(temporary, file, ec);
    if (!ec) return true;
  }
  fs::remove(temporary, ec);
  return false;
}

}  // namespace nelf
