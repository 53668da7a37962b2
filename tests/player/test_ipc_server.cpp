// The socket of --input-ipc-server (player/ipc_server): owner-only, its lines answered one by one
// (several in one write, one split over two), replaced when a stale socket is in the way, refused
// over anything else, removed at the end.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>

#include "core/user_error.hpp"
#include "player/ipc_server.hpp"
#include "support/test_support.hpp"

namespace nelf::playback {
namespace {

UniqueFd connect_to(const std::filesystem::path& path) {
  UniqueFd fd = test::connect_unix_socket(path);
  EXPECT_GE(fd.get(), 0) << std::strerror(errno);
  return fd;
}

void send_text(const UniqueFd& fd, const std::string& text) {
  ASSERT_EQ(::send(fd.get(), text.data(), text.size(), MSG_NOSIGNAL), static_cast<ssize_t>(text.size()));
}

// Polls `server` until `fd` has received `lines` newlines (or 5 s went by); what it received.
std::string replies(IpcServer& server, const UniqueFd& fd, const IpcServer::Handler& handle, int lines) {
  std::string got;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (std::count(got.begin(), got.end(), '\n') < lines && std::chrono::steady_clock::now() < until) {
    server.poll(handle);
    char buffer[256];
    const ssize_t n = ::recv(fd.get(), buffer, sizeof buffer, MSG_DONTWAIT);
    if (n > 0) got.append(buffer, static_cast<std::size_t>(n));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return got;
}

TEST(IpcServer, AnswersEachLineOnAnOwnerOnlySocketAndRemovesIt) {
  test::TempDir dir;
  const auto path = dir / "nelf.sock";
  {
    IpcServer server(path.string());
    struct stat st {};
    ASSERT_EQ(::lstat(path.c_str(), &st), 0);
    EXPECT_TRUE(S_ISSOCK(st.st_mode));
    EXPECT_EQ(st.st_mode & 0777, 0600u);

    std::vector<std::string> seen;
    const IpcServer::Handler echo = [&](std::string_view line) {
      seen.emplace_back(line);
      return line == "quiet" ? std::string() : "re:" + std::string(line);
    };
    const UniqueFd client = connect_to(path);
    send_text(client, "one\ntwo\r\nquiet\nthr");
    EXPECT_EQ(replies(server, client, echo, 2), "re:one\nre:two\n");
    send_text(client, "ee\n\n");
    EXPECT_EQ(replies(server, client, echo, 1), "re:three\n");
    EXPECT_EQ(seen, (std::vector<std::string>{"one", "two", "quiet", "three"}));
    EXPECT_EQ(server.clients(), 1u);
  }
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(path)));
}

TEST(IpcServer, AClientThatHangsUpIsAnsweredThenDropped) {
  test::TempDir dir;
  const auto path = dir / "nelf.sock";
  IpcServer server(path.string());
  const UniqueFd client = connect_to(path);
  send_text(client, "last\n");
  ASSERT_EQ(::shutdown(client.get(), SHUT_WR), 0);  // as `echo … | socat` does
  const IpcServer::Handler echo = [](std::string_view line) { return std::string(line); };
  EXPECT_EQ(replies(server, client, echo, 1), "last\n");
  EXPECT_EQ(server.clients(), 0u);
}

TEST(IpcServer, AStaleSocketIsReplacedAnythingElseRefused) {
  test::TempDir dir;
  const auto path = dir / "nelf.sock";
  {
    // A socket left behind: bound, never removed.
    UniqueFd stale(::socket(AF_UNIX, SOCK_STREAM, 0));
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::strncpy(address.sun_path, path.c_str(), sizeof(address.sun_path) - 1);
    ASSERT_EQ(::bind(stale.get(), reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0);
  }
  ASSERT_TRUE(std::filesystem::is_socket(path));
  { IpcServer server(path.string()); }
  EXPECT_FALSE(std::filesystem::exists(path));

  test::write_file(path, "mine");
  try {
    IpcServer server(path.string());
    FAIL() << "a regular file was replaced";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), "--input-ipc-server " + path.string() + ": exists and is not a socket");
    EXPECT_EQ(e.status(), 2);
  }
  EXPECT_EQ(test::read_file(path), "mine");
  EXPECT_THROW(IpcServer((dir / "no-such-dir" / "nelf.sock").string()), UserError);
  EXPECT_THROW(IpcServer(std::string(200, 'x')), UserError);
}

}  // namespace
}  // namespace nelf::playback
