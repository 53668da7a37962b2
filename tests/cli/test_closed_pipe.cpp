// nelf's output into a pipe whose reader went away (`nelf probe --json IN | head -c1`, `nelf
// profiles | head -1`, a progress log piped into a pager that quit): a quiet end, never a death by
// SIGPIPE in the middle of a file, never an error message about the pipe.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf::test {
namespace {

// The end of a command whose stdout or stderr was a pipe nobody reads any more.
struct ClosedPipeResult {
  bool signalled = false;  // killed by a signal (`status` is then the signal number)
  int status = -1;         // exit status otherwise
  std::string captured;    // what the other stream (stderr or stdout) carried
};

// Runs the shell command `exec COMMAND` with file descriptor `fd` (1 or 2) the writing end of a pipe
// whose reading end is already closed (a reader that went away: `| head -c1` once head has its
// byte), SIGPIPE at its default action as a shell leaves it, the other stream captured. `exec`:
// the status is the program's own, not a shell's 128 + signal.
ClosedPipeResult run_into_closed_pipe(const std::string& command, int fd) {
  TempDir dir;
  const auto captured_path = dir / "captured";
  const std::string other = fd == 1 ? " 2>" : " >";
  const std::string line = "exec " + command + other + q(captured_path) + " </dev/null";
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error("cannot make a pipe");
  ::close(fds[0]);  // nobody will read: every write fails (EPIPE) or raises SIGPIPE
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("cannot fork");
  if (pid == 0) {
    std::signal(SIGPIPE, SIG_DFL);
    ::dup2(fds[1], fd);
    ::close(fds[1]);
    ::execl("/bin/sh", "sh", "-c", line.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(fds[1]);
  int raw = 0;
  while (::waitpid(pid, &raw, 0) < 0)
    if (errno != EINTR) throw std::runtime_error("cannot wait for the command");
  ClosedPipeResult r;
  r.signalled = WIFSIGNALED(raw);
  r.status = r.signalled ? WTERMSIG(raw) : WEXITSTATUS(raw);
  r.captured = read_file(captured_path);
  return r;
}

// stdout into a closed pipe: no message, and the status of a program that SIGPIPE ended (141),
// returned after cleaning up rather than by being killed.
TEST(ClosedPipe, StdoutEndsQuietly) {
  TempDir dir;
  make_media(dir / "clip.mkv", two_colour_input(64, 36, false, 2));
  const std::vector<std::string> commands = {
      "probe --json " + q(dir / "clip.mkv"), "probe " + q(dir / "clip.mkv"), "design --json", "design", "profiles",
  };
  for (const auto& args : commands) {
    SCOPED_TRACE(args);
    const auto r = run_into_closed_pipe(std::string(NELF_BINARY) + " " + args, 1);
    EXPECT_FALSE(r.signalled) << "killed by signal " << r.status;
    EXPECT_EQ(r.status, 141);
    EXPECT_EQ(r.captured, "");  // stderr
  }
}

// stderr into a closed pipe while a conversion writes a file: the progress lines (every 5 s when
// stderr is not a terminal, then "wrote ...") are dropped and the conversion finishes, whole.
// SIGPIPE used to kill nelf at the first of them: mid-conversion, its temporary file left behind.
TEST(ClosedPipe, ConversionOutlivesAClosedStderr) {
  TempDir dir;
  const auto profile = write_small_profile(dir);
  const auto r = run_into_closed_pipe(std::string(NELF_BINARY) + " convert synthetic:duration=3,size=320x180 " +
                                          q(dir / "out.mkv") + " --codec utvideo --no-audio --profile " + q(profile),
                                      2);
  EXPECT_FALSE(r.signalled) << "killed by signal " << r.status;
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.captured, "");  // stdout
  EXPECT_EQ(files_in(dir.path()), (std::vector<std::string>{"out.mkv", "small.toml"}));
  const auto frames = run_command(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=nb_read_frames -of csv=p=0 " +
      q(dir / "out.mkv"));
  EXPECT_EQ(frames.out, "72\n") << frames.err;  // 3 s at the synthetic clip's 24 fps
}

}  // namespace
}  // namespace nelf::test
