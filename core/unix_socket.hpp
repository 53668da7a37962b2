#pragma once
// Unix sockets for what talks to nelf locally: mpv's JSON IPC (player/ipc_server) and a game's
// quad-buffer interposer (inputs/glx_stereo_source).
#include <string>

namespace nelf {

// A file descriptor, closed with its owner.
class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  ~UniqueFd();
  UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept;
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  int get() const { return fd_; }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

 private:
  int fd_ = -1;
};

// A non-blocking stream socket listening at `path`, readable and writable by the owner only (0600)
// from the moment it exists. A socket already there (a program that did not exit cleanly) is
// replaced, as mpv does; anything else there is refused. Throws UserError (status 2) as
// "`what` PATH: why".
UniqueFd listen_on_unix_socket(const std::string& path, const std::string& what);

}  // namespace nelf
