#include "support/x11_close_window.hpp"

#include <X11/Xlib.h>

#include <stdexcept>

namespace nelf::test {

void request_window_close(const std::string& display_name, const std::string& window_id) {
  ::Display* x = XOpenDisplay(display_name.c_str());
  if (!x) throw std::runtime_error("cannot open X display " + display_name);
  XEvent event{};
  event.xclient.type = ClientMessage;
  event.xclient.window = std::stoul(window_id);
  event.xclient.message_type = XInternAtom(x, "WM_PROTOCOLS", False);
  event.xclient.format = 32;
  event.xclient.data.l[0] = static_cast<long>(XInternAtom(x, "WM_DELETE_WINDOW", False));
  event.xclient.data.l[1] = CurrentTime;
  XSendEvent(x, event.xclient.window, False, NoEventMask, &event);
  XSync(x, False);
  XCloseDisplay(x);
}

}  // namespace nelf::test
