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

}  // namespace

IpcServer::IpcServer(std::string path)
    : path_(std::move(path)), listener_(listen_on_unix_socket(path_, "--input-ipc-server")) {}

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
