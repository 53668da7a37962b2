#pragma once
// Helpers shared by the tests: temporary directories, running the nelf binary, small profiles.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/unix_socket.hpp"

namespace nelf::test {

// A fresh directory under the system temp dir, removed with everything in it on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// The names of the entries of `dir`, sorted (to check that nothing was left behind).
std::vector<std::string> files_in(const std::filesystem::path& dir);

// Writes `text` to `path` (creating or replacing it).
void write_file(const std::filesystem::path& path, const std::string& text);
std::string read_file(const std::filesystem::path& path);

struct CommandResult {
  int status = -1;  // exit status, or 128 + signal number when killed by a signal
  std::string out;
  std::string err;
};

// Runs a shell command line (through /bin/sh), capturing stdout and stderr separately.
CommandResult run_command(const std::string& command_line);

#ifdef NELF_BINARY
// Runs `nelf ARGS` (ARGS is a shell-quoted string).
inline CommandResult run_nelf(const std::string& args) { return run_command(std::string(NELF_BINARY) + " " + args); }

// Runs a failing `nelf ARGS` and checks the contract of DESIGN.md §11: `status` (not a signal),
// nothing on stdout, exactly one line on stderr starting "nelf: " and containing `expected`, and
// `dir` exactly as it was (no output, no temporary file).
void expect_clean_failure(const TempDir& dir, const std::string& args, int status, const std::string& expected);
#endif

// Sets (value null: unsets) an environment variable for the scope of a test, and the nelf
// processes it starts; restores it after.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value);
  ScopedEnv(const char* name, const std::string& value) : ScopedEnv(name, value.c_str()) {}
  ~ScopedEnv();
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

// Writes `dir`/`name`, one frame of the ffmpeg CLI's lavfi `source` (e.g. "testsrc2=s=512x144")
// through the filter graph `filters` (none when empty), and returns its path; a failed ffmpeg run
// fails the test.
std::filesystem::path write_lavfi_still(const TempDir& dir, const std::string& name, const std::string& source,
                                        const std::string& filters = "");

// Quotes a string for /bin/sh.
std::string shell_quote(const std::string& s);
// A path quoted for /bin/sh: the shorthand the command lines of the tests are written with.
inline std::string q(const std::filesystem::path& p) { return shell_quote(p.string()); }

// A stream socket connected to the Unix socket at `path`, as a client of nelf's (an IPC client, a
// game's interposer); none (and errno saying why) when nothing listens there.
UniqueFd connect_unix_socket(const std::filesystem::path& path);

// The hmz-t1 optics (1.0 mm / f 3.3 mm sheet, 25 mm eye relief, image at 1 m) on half the pixels per
// axis at twice the pitch (640x360 at 24 um): the same lens block, field of view, eye box and beams,
// a quarter of the pixels to composite and a retinal grid of about 210x120, so that the suites that
// simulate the eye stay fast (also under ASan). A profile's TOML text, named "small".
extern const char* const half_resolution_hmz_toml;

// Writes `dir`/small.toml and returns its path: a light-field profile with a 160x90 panel (the
// HMZ-T1's physical size) so that llvmpipe and the CPU reference composite in milliseconds. Its
// signal is the HMZ-T1's (hdmi-fp-720p60): the panel sits centred in each 1280x720 eye area.
std::filesystem::path write_small_profile(const TempDir& dir);

}  // namespace nelf::test
