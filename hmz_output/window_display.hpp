#pragma once
// The GLFW live outputs (DESIGN.md §7): a desktop window showing the packed frame scaled to fit,
// fullscreen 1:1 on a chosen monitor, and quad-buffer stereo (left/right back buffers). X11 + GLX,
// OpenGL 4.5 core.
#include <memory>

#include "hmz_output/display.hpp"

namespace nelf {

// Opens a display of kind OutputKind::window, fullscreen or quad_buffer; its context is current on
// the calling thread, which must be the main thread (GLFW's rule) and must make every later call.
// Throws std::runtime_error with one actionable line when there is no X display, GLFW cannot start,
// OpenGL 4.5 core is unavailable, the monitor is not found or not in the packed mode (fullscreen),
// or the driver offers no stereo visuals (quad-buffer); std::invalid_argument for another kind or an
// empty packed size.
std::unique_ptr<Display> open_window_display(const DisplayOptions& options);

}  // namespace nelf
