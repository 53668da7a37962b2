#pragma once
// `--input-ipc-server=PATH`: a Unix socket that mpv's JSON IPC clients and scripts connect to
// (one request a line, one reply a line). This is the transport: the socket, its clients and their
// lines; what a line asks of the player is player/ipc_commands'. It never blocks: the play loop
// polls it once a refresh, so that every request runs on the loop's thread.
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "core/unix_socket.hpp"

namespace nelf::playback {

using nelf::UniqueFd;

class IpcServer {
 public:
  // Listens on `path`, readable and writable by the owner only (0600). A socket already there (a
  // player that did not exit cleanly) is replaced, as mpv does; anything else there is refused.
  // Throws UserError (status 2) for a path that is not a socket, too long or cannot be bound.
  explicit IpcServer(std::string path);
  // Closes every connection and removes the socket.
  ~IpcServer();
  IpcServer(const IpcServer&) = delete;
  IpcServer& operator=(const IpcServer&) = delete;

  // A request line (without its newline) → the reply line to send back (without its newline), or
  // "" for none.
  using Handler = std::function<std::string(std::string_view line)>;
  // Accepts waiting connections, reads what the clients sent and answers each whole line with
  // `handle`; sends what is still queued. Never blocks; a client that hung up or stopped reading
  // its replies is dropped.
  void poll(const Handler& handle);

  const std::string& path() const { return path_; }
  std::size_t clients() const { return clients_.size(); }

 private:
  struct Client {
    UniqueFd fd;
    std::string in, out;
    bool closed = false;
  };
  void read_from(Client& client, const Handler& handle);
  static void flush(Client& client);

  std::string path_;
  UniqueFd listener_;
  std::vector<Client> clients_;
};

}  // namespace nelf::playback
