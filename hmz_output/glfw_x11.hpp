#pragma once
// What the window outputs need from X11 beyond GLFW: monitors' EDID names and surviving the loss of
// the X connection. Its own file because Xlib's headers define macros (KeyPress, Display) that clash
// with nelf's names.
#include <string>

struct GLFWmonitor;

namespace nelf {

// The monitor's own name from the EDID its output reports (e.g. "HMZ-T1"), "" when unknown.
std::string glfw_monitor_model(GLFWmonitor* monitor);

// Xlib's default reaction to a lost X connection (the server exited, the session ended) is to print
// "XIO: fatal IO error" and exit(). After this call (once GLFW is initialised) it returns instead,
// leaving the connection unusable, and x_connection_lost() turns true so that the display can throw
// an exception the caller handles like any other.
void survive_x_connection_loss();
bool x_connection_lost();

}  // namespace nelf
