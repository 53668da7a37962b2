#pragma once
// `glx-stereo:[wait=S,]socket=PATH`: what an OpenGL game swaps, live, from nelf's interposer loaded
// into the game (inputs/glx_interposer/, inputs/glx_stereo_protocol.hpp): a quad-buffer game's two
// eyes, or the picture of a game that draws both eyes into one, split by its layout (detected as
// for a file, or --layout). nelf listens at PATH; the game, started with
// LD_PRELOAD=nelf-glx-stereo.so and NELF_GLX_STEREO_SOCKET=PATH, connects at its first swap.
// `nelf run` does this by itself.
#include <string>
#include <string_view>

#include "core/user_error.hpp"

namespace nelf {

struct GlxStereoSpec {
  std::string socket;
  double wait_s = 60;  // for the game's first swap
};

bool is_glx_stereo_spec(std::string_view input);
GlxStereoSpec parse_glx_stereo_spec(const std::string& input);  // throws UserError (status 2)

// The game did not swap an OpenGL buffer within the wait: not an OpenGL game, or not one drawn
// through GLX. `nelf run` says so and waits for its window.
class GameDidNotSwap : public UserError {
 public:
  using UserError::UserError;
};

// Where nelf-glx-stereo.so is (core/module_path.hpp); $NELF_GLX_STEREO_LIBRARY names it explicitly.
std::string glx_stereo_library_path();

}  // namespace nelf
