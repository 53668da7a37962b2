#pragma once
// The GLFW packed-frame outputs (DESIGN.md §7): a desktop window showing the packed frame scaled to
// fit, and fullscreen 1:1 on a chosen monitor (quad-buffer stereo is quad_buffer_display.cpp; what
// they share, glfw_window.hpp). X11 + GLX, OpenGL 4.5 core.
#include <memory>

#include "hmz_output/display.hpp"

namespace nelf {

// How a GLFW display shows the packed frame (each a row of output_drivers.cpp).
enum class WindowMode { window, fullscreen };

// Opens a display in `mode`; its context is current on
// the calling thread, which must be the main thread (GLFW's rule) and must make every later call.
// Throws std::runtime_error with one actionable line when there is no X display, GLFW cannot start,
// OpenGL 4.5 core is unavailable, the monitor is not found or not in the packed mode (fullscreen),
// (quad-buffer: or the driver offers no stereo visuals); std::invalid_argument for an empty packed size (quad-buffer:
// or a signal that does not carry both eyes). The window belongs to the context: it closes when both the display and
// every holder of context() (e.g. a GlCompositor) are gone. Destroy the compositor first to close it with the display.
// vsync() is false on software renderers and without GLX swap control; otherwise a few swaps with
// interval 1 are timed at opening (swap_timing.hpp). refresh_hz(): the monitor's mode, else the
// signal's timing, else 60. Losing the X server makes present()/poll_events() throw and
// close_requested() true instead of Xlib ending the process.
std::unique_ptr<Display> open_window_display(const DisplayOptions& options, WindowMode mode);

}  // namespace nelf
