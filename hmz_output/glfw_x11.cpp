#include "hmz_output/glfw_x11.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#define GLFW_EXPOSE_NATIVE_X11
#include <GLFW/glfw3native.h>
#include <X11/Xatom.h>
#include <X11/extensions/Xrandr.h>

#include <atomic>
#include <vector>

#include "hmz_output/monitor_selection.hpp"

namespace nelf {

std::string glfw_monitor_model(GLFWmonitor* monitor) {
  ::Display* x_display = glfwGetX11Display();
  const RROutput output = glfwGetX11Monitor(monitor);
  if (!x_display || !output) return {};
  const Atom edid_atom = XInternAtom(x_display, "EDID", True);
  if (edid_atom == None) return {};  // no output has ever reported an EDID
  unsigned char* data = nullptr;
  Atom actual_type = None;
  int actual_format = 0;
  unsigned long items = 0, bytes_after = 0;
  // 256 32-bit units: the base block and a few extensions, more than the name needs.
  if (XRRGetOutputProperty(x_display, output, edid_atom, 0, 256, False, False, AnyPropertyType, &actual_type,
                           &actual_format, &items, &bytes_after, &data) != Success)
    return {};
  std::vector<unsigned char> bytes;
  if (data && actual_format == 8) bytes.assign(data, data + items);
  if (data) XFree(data);
  return edid_monitor_name(bytes);
}

namespace {

std::atomic<bool> connection_lost{false};

void on_connection_lost(::Display* /*display*/, void* /*user_data*/) { connection_lost = true; }

// The process-wide handler runs first; Xlib's default one prints its own message and exits.
int on_io_error(::Display* /*display*/) {
  connection_lost = true;
  return 0;
}

}  // namespace

void survive_x_connection_loss() {
  connection_lost = false;
  XSetIOErrorHandler(on_io_error);
  if (::Display* x_display = glfwGetX11Display()) XSetIOErrorExitHandler(x_display, on_connection_lost, nullptr);
}

bool x_connection_lost() { return connection_lost; }

}  // namespace nelf
