#pragma once
// The EDID name of a GLFW monitor, read through X11/RandR. Its own file because Xlib's headers
// define macros (KeyPress, Display) that clash with nelf's names.
#include <string>

struct GLFWmonitor;

namespace nelf {

// The monitor's own name from the EDID its output reports (e.g. "HMZ-T1"), "" when unknown.
std::string glfw_monitor_model(GLFWmonitor* monitor);

}  // namespace nelf
