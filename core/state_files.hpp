#pragma once
// Files nelf keeps between runs under the XDG state directory: where play stopped (player/
// watch_later) and the ScreenCast portal's kept choice (inputs/screencast_portal). Both are
// replaced whole, so a run cut off mid-write never leaves half a file for the next one to read.
#include <sys/types.h>
#include <filesystem>
#include <string>

namespace nelf {

// $XDG_STATE_HOME when it is an absolute path (the XDG spec says to ignore a relative one), else
// $HOME/.local/state; empty without HOME (then nothing is kept).
std::filesystem::path xdg_state_home();

// Writes `text` to a temporary file beside `file` (created with `mode`, less the umask) and renames
// it over `file`, creating the folders; false, leaving `file` as it was, when any step fails.
bool replace_file(const std::filesystem::path& file, const std::string& text, mode_t mode = 0666);

}  // namespace nelf
