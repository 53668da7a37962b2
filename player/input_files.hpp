#pragma once
// The files a command reads, so that no output is ever written over one of them (ffmpeg's "Output
// same as Input"). -y replaces an existing output, never an input: `nelf convert x.mkv x.mkv -y`
// would otherwise read the movie while replacing it, and lose it.
#include <sys/types.h>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace nelf {

class InputFiles {
 public:
  // Records the input `path`, as given on the command line, under `role` (e.g. "the input",
  // "the --right view"). Names that are not local files are ignored: `synthetic:` specs, URLs,
  // pipes, built-in profile names, and files that do not exist (they cannot be overwritten).
  void add(const std::string& path, std::string role);

  // Throws UserError (status 2) naming the input when `output` is one of the inputs: the same path
  // once resolved (./x, ../dir/x, symlinks anywhere in it, the output name itself a symlink to the
  // input), or the same file under another name (a hard link, a bind mount): the same device and
  // inode. Cheap (a few system calls): image sequences check every frame's name.
  void refuse_as_output(const std::string& output) const;

 private:
  struct Input {
    std::string shown;  // as given
    std::string role;
    std::filesystem::path resolved;
    dev_t device = 0;
    ino_t inode = 0;
  };
  std::vector<Input> inputs_;
};

}  // namespace nelf
