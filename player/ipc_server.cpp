#include "player/ipc_server.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "core/user_error.hpp"

namespace nelf::playback {

namespace {

// A client's requests, unanswered, or replies it does not read, up to this much: beyond it the
// client is dropped rather than nelf's memory growing for it.
constexpr std::size_t max_buffered = 1 << 20;

[[noreturn]] void refuse(const std::string& path, const std::string& why) {
  throw UserError(fmt::format("--input-ipc-server {}: {}", path, why), 2);
}

}  // namespace

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

IpcServer::IpcServer(std::string path) : path_(std::move(path)) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path_.empty() || path_.size() >= sizeof(address.sun_path))
    refuse(path_, fmt::format("a socket's path must be 1 to {} bytes long", sizeof(address.sun_path) - 1));
  std::memcpy(address.sun_path, path_.c_str(), path_.size() + 1);

  struct stat there {};
  if (::lstat(path_.c_str(), &there) == 0) {
    if (!S_ISSOCK(there.st_mode)) refuse(path_, "exists and is not a socket");
    if (::unlink(path_.c_str()) != 0) refuse(path_, std::strerror(errno));
  }

  listener_ = UniqueFd(::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (listener_.get() < 0) refuse(path_, std::strerror(errno));
  // Owner-only from the moment it exists: the socket drives the player, so nobody else may
  // connect even between bind() and a chmod().
  const mode_t old_mask = ::umask(0177);
  const int bound = ::bind(listener_.get(), reinterpret_cast<const sockaddr*>(&address), sizeof(address));
  const int bind_errno = errno;
  ::umask(old_mask);
  if (bound != 0) refuse(path_, std::strerror(bind_errno));
  if (::chmod(path_.c_str(), 0600) != 0 || ::listen(listener_.get(), 8) != 0) {
    const int e = errno;
    ::unlink(path_.c_str());
    refuse(path_, std::strerror(e));
  }
}

IpcServer::~IpcServer() {
  clients_.clear();
  listener_ = UniqueFd();
  ::unlink(path_.c_str());
}

void IpcServer::poll(const Handler& handle) {
  for (;;) {
    UniqueFd fd(::accept4(listener_.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC));
    if (fd.get() < 0) break;  // none waiting (EAGAIN), or one that went away before it was accepted
    clients_.push_back(Client{std::move(fd), {}, {}, false});
  }
  for (Client& client : clients_) {
    read_from(client, handle);
    flush(client);
  }
  std::erase_if(clients_, [](const Client& c) { return c.closed; });
}

void IpcServer::read_from(Client& client, const Handler& handle) {
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::recv(client.fd.get(), buffer, sizeof buffer, 0);
    if (n > 0) {
      client.in.append(buffer, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    // End of file: the client sent its last request and shut its side (`echo … | socat`); what it
    // sent is still answered below, and its replies sent before it is dropped.
    if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) client.closed = true;
    break;
  }
  std::size_t start = 0;
  for (std::size_t end; (end = client.in.find('\n', start)) != std::string::npos; start = end + 1) {
    std::string_view line(client.in.data() + start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.find_first_not_of(" \t") == std::string_view::npos) continue;
    const std::string reply = handle(line);
    if (!reply.empty()) client.out += reply + "\n";
  }
  client.in.erase(0, start);
  if (client.in.size() > max_buffered) client.closed = true;
}

void IpcServer::flush(Client& client) {
  while (!client.out.empty()) {
    const ssize_t n = ::send(client.fd.get(), client.out.data(), client.out.size(), MSG_NOSIGNAL);
    if (n > 0) {
      client.out.erase(0, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      if (client.out.size() > max_buffered) client.closed = true;
      return;
    }
    client.closed = true;  // it hung up
    client.out.clear();
    return;
  }
}

}  // namespace nelf::playback
