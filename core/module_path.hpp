#pragma once
// Where one of the libraries nelf installs in its private folder lib/nelf is: the image library
// module (core/image_library) and the quad-buffer interposer it loads into games
// (inputs/glx_interposer).
#include <filesystem>

namespace nelf {

// $`variable` when set (an explicit file: tests, unusual installs); else the first that exists of:
// beside the executable as installed (bin/../lib/nelf/`file_name`, so that a relocated install
// works), `installed` (the configured prefix), `built` (the build tree, for nelf run from there).
// When none exists, the one beside the executable, for the error message.
std::filesystem::path find_module(const char* variable, const char* file_name, const char* installed,
                                  const char* built);

}  // namespace nelf
