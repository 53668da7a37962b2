#pragma once
// Closing another process's X11 window the way a window manager's close button does, for tests of
// programs run as child processes (Xlib's macros stay out of the test files: they clash with
// GoogleTest's and OpenImageIO's names).
#include <string>

namespace nelf::test {

// Sends WM_DELETE_WINDOW to window `window_id` (decimal, as xdotool prints it) on X display
// `display_name`. Throws std::runtime_error when the display cannot be opened.
void request_window_close(const std::string& display_name, const std::string& window_id);

}  // namespace nelf::test
