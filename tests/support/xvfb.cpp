#include "support/xvfb.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace nelf::test {

namespace {

// Waits up to `seconds` for `pid` to exit; true when it was reaped.
bool reap_within(pid_t pid, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (true) {
    int status = 0;
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid || (r < 0 && errno == ECHILD)) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

}  // namespace

XvfbServer::XvfbServer(int width, int height, double timeout_seconds) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("Xvfb: pipe failed: ") + std::strerror(errno));
  const int read_end = fds[0], write_end = fds[1];
  const std::string fd_text = std::to_string(write_end);
  const std::string screen = std::to_string(width) + "x" + std::to_string(height) + "x24";

  pid_ = fork();
  if (pid_ < 0) {
    close(read_end);
    close(write_end);
    throw std::runtime_error(std::string("Xvfb: fork failed: ") + std::strerror(errno));
  }
  if (pid_ == 0) {
    // Child: the write end must survive exec (Xvfb writes the display number to it); the server's
    // chatter goes to /dev/null so that test output stays readable.
    fcntl(write_end, F_SETFD, 0);
    const int null_fd = open("/dev/null", O_RDWR);
    if (null_fd >= 0) {
      dup2(null_fd, STDIN_FILENO);
      dup2(null_fd, STDOUT_FILENO);
      dup2(null_fd, STDERR_FILENO);
    }
    // -noreset: by default the server resets when its last client disconnects, and a test that
    // opens a second display after closing the first would race that reset.
    execlp("Xvfb", "Xvfb", "-displayfd", fd_text.c_str(), "-screen", "0", screen.c_str(), "-nolisten", "tcp",
           "-noreset", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(write_end);

  // Xvfb writes "N\n" once it accepts connections.
  std::string number;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_seconds);
  std::string failure;
  while (failure.empty()) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      failure = "did not report a display within " + std::to_string(timeout_seconds) + " s";
      break;
    }
    pollfd p{read_end, POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;
    char buffer[32];
    const ssize_t n = read(read_end, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      failure = "exited before reporting a display (is the xvfb package installed?)";
      break;
    }
    number.append(buffer, static_cast<std::size_t>(n));
    if (number.find('\n') != std::string::npos) break;
  }
  close(read_end);
  if (failure.empty()) {
    number = number.substr(0, number.find('\n'));
    if (number.empty() || number.find_first_not_of("0123456789") != std::string::npos)
      failure = "reported an unreadable display '" + number + "'";
  }
  if (!failure.empty()) {
    kill(pid_, SIGKILL);
    reap_within(pid_, 5.0);
    pid_ = -1;
    throw std::runtime_error("Xvfb " + failure);
  }
  display_name_ = ":" + number;
}

XvfbServer::~XvfbServer() {
  if (pid_ <= 0) return;
  kill(pid_, SIGTERM);
  if (!reap_within(pid_, 1.0)) {
    kill(pid_, SIGKILL);
    reap_within(pid_, 5.0);
  }
}

// WNOWAIT: the destructor reaps it, as for a server that still runs.
bool XvfbServer::running() const {
  siginfo_t info{};
  return pid_ > 0 && waitid(P_PID, static_cast<id_t>(pid_), &info, WEXITED | WNOHANG | WNOWAIT) == 0 &&
         info.si_pid == 0;
}

void XvfbServer::kill_now() {
  if (pid_ <= 0) return;
  kill(pid_, SIGKILL);
  reap_within(pid_, 5.0);
  pid_ = -1;
}

ScopedDisplay::ScopedDisplay(const std::string& display) {
  if (const char* previous = std::getenv("DISPLAY")) {
    had_previous_ = true;
    previous_ = previous;
  }
  if (display.empty())
    unsetenv("DISPLAY");
  else
    setenv("DISPLAY", display.c_str(), 1);
}

ScopedDisplay::~ScopedDisplay() {
  if (had_previous_)
    setenv("DISPLAY", previous_.c_str(), 1);
  else
    unsetenv("DISPLAY");
}

}  // namespace nelf::test
