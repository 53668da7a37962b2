#include "support/test_support.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

namespace nelf::test {

TempDir::TempDir() {
  std::random_device rd;
  const auto base = std::filesystem::temp_directory_path();
  for (int attempt = 0; attempt < 100; ++attempt) {
    auto candidate = base / ("nelf-test-" + std::to_string(rd()));
    if (std::filesystem::create_directory(candidate)) {
      path_ = candidate;
      return;
    }
  }
  throw std::runtime_error("cannot create a temporary directory");
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

UniqueFd connect_unix_socket(const std::filesystem::path& path) {
  UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strncpy(address.sun_path, path.c_str(), sizeof(address.sun_path) - 1);
  if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) return UniqueFd();
  return fd;
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

CommandResult run_command(const std::string& command_line) {
  TempDir dir;
  const auto out_path = dir / "stdout";
  const auto err_path = dir / "stderr";
  const std::string full = "( " + command_line + " ) >" + q(out_path) + " 2>" + q(err_path) + " </dev/null";
  const int raw = std::system(full.c_str());
  CommandResult r;
  if (raw == -1) throw std::runtime_error("cannot run: " + command_line);
  if (WIFEXITED(raw))
    r.status = WEXITSTATUS(raw);
  else if (WIFSIGNALED(raw))
    r.status = 128 + WTERMSIG(raw);
  r.out = read_file(out_path);
  r.err = read_file(err_path);
  return r;
}

const char* const half_resolution_hmz_toml = R"(
name = "small"
[display]
resolution = [640, 360]
pixel_pitch_mm = 0.024
[lens_array]
pitch_mm = 1.0
focal_length_mm = 3.3
[viewing]
eye_relief_mm = 25.0
virtual_image_mm = 1000.0
pupil_mm = 4.0
ipd_mm = 63.0
)";

std::filesystem::path write_small_profile(const TempDir& dir) {
  const auto path = dir / "small.toml";
  write_file(path, R"(name = "small"
[display]
resolution = [160, 90]
pixel_pitch_mm = 0.096
[lens_array]
pitch_mm = 1.0
focal_length_mm = 3.3
[viewing]
eye_relief_mm = 25.0
virtual_image_mm = 1000.0
)");
  return path;
}

std::filesystem::path write_lavfi_still(const TempDir& dir, const std::string& name, const std::string& source,
                                        const std::string& filters) {
  const auto path = dir / name;
  const CommandResult r =
      run_command("ffmpeg -loglevel error -f lavfi -i " + shell_quote(source) +
                  (filters.empty() ? "" : " -vf " + shell_quote(filters)) + " -frames:v 1 " + q(path));
  EXPECT_EQ(r.status, 0) << r.err;
  return path;
}

std::vector<std::string> files_in(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

#ifdef NELF_BINARY
void expect_clean_failure(const TempDir& dir, const std::string& args, int status, const std::string& expected) {
  SCOPED_TRACE(args);
  const auto before = files_in(dir.path());
  const auto r = run_nelf(args);
  EXPECT_EQ(r.status, status) << r.err;
  EXPECT_LT(r.status, 128) << "killed by a signal";
  EXPECT_EQ(r.out, "");
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(r.err.rfind("nelf: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  EXPECT_EQ(files_in(dir.path()), before);
}
#endif

ScopedEnv::ScopedEnv(const char* name, const char* value) : name_(name) {
  if (const char* old = std::getenv(name)) old_ = old;
  if (value)
    setenv(name, value, 1);
  else
    unsetenv(name);
}

ScopedEnv::~ScopedEnv() {
  if (old_)
    setenv(name_, old_->c_str(), 1);
  else
    unsetenv(name_);
}

}  // namespace nelf::test
