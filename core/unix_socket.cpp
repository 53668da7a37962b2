#include "core/unix_socket.hpp"

#include <fmt/format.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/user_error.hpp"

namespace nelf {

UniqueFd::~UniqueFd() {
  if (fd_ >= 0) ::close(fd_);
}

UniqueFd& UniqueFd::operator=(UniqueFd&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.release();
  }
  return *this;
}

UniqueFd listen_on_unix_socket(const std::string& path, const std::string& what) {
  const auto refuse = [&](const std::string& why) { return UserError(fmt::format("{} {}: {}", what, path, why), 2); };
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof(address.sun_path))
    throw refuse(fmt::format("a socket's path must be 1 to {} bytes long", sizeof(address.sun_path) - 1));
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);

  struct stat there {};
  if (::lstat(path.c_str(), &there) == 0) {
    if (!S_ISSOCK(there.st_mode)) throw refuse("exists and is not a socket");
    if (::unlink(path.c_str()) != 0) throw refuse(std::strerror(errno));
  }

  UniqueFd listener(::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (listener.get() < 0) throw refuse(std::strerror(errno));
  // Owner-only from the moment it exists: nobody else may connect even between bind() and a chmod().
  const mode_t old_mask = ::umask(0177);
  const int bound = ::bind(listener.get(), reinterpret_cast<const sockaddr*>(&address), sizeof(address));
  const int bind_errno = errno;
  ::umask(old_mask);
  if (bound != 0) throw refuse(std::strerror(bind_errno));
  if (::chmod(path.c_str(), 0600) != 0 || ::listen(listener.get(), 8) != 0) {
    const int e = errno;
    ::unlink(path.c_str());
    throw refuse(std::strerror(e));
  }
  return listener;
}

}  // namespace nelf
