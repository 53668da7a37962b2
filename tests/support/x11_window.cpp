#include "support/x11_window.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#define GLFW_EXPOSE_NATIVE_X11
#include <GLFW/glfw3native.h>
#include <X11/Xlib.h>
#include <X11/Xutil.h>

#include <stdexcept>

namespace nelf::test {

WindowCapture capture_window(GLFWwindow* window) {
  ::Display* display = glfwGetX11Display();
  const Window x_window = glfwGetX11Window(window);
  if (!display || !x_window) throw std::runtime_error("capture_window: not an X11 window");
  XSync(display, False);
  XWindowAttributes attributes{};
  if (!XGetWindowAttributes(display, x_window, &attributes))
    throw std::runtime_error("capture_window: no window attributes");
  XImage* image = XGetImage(display, x_window, 0, 0, static_cast<unsigned>(attributes.width),
                            static_cast<unsigned>(attributes.height), AllPlanes, ZPixmap);
  if (!image) throw std::runtime_error("capture_window: XGetImage failed (window not viewable?)");
  WindowCapture capture;
  capture.width = attributes.width;
  capture.height = attributes.height;
  capture.rgb.resize(static_cast<std::size_t>(capture.width) * capture.height * 3);
  for (int y = 0; y < capture.height; ++y)
    for (int x = 0; x < capture.width; ++x) {
      const unsigned long pixel = XGetPixel(image, x, y);
      const std::size_t i = (static_cast<std::size_t>(y) * capture.width + x) * 3;
      capture.rgb[i] = static_cast<unsigned char>((pixel & image->red_mask) >> __builtin_ctzl(image->red_mask));
      capture.rgb[i + 1] = static_cast<unsigned char>((pixel & image->green_mask) >> __builtin_ctzl(image->green_mask));
      capture.rgb[i + 2] = static_cast<unsigned char>((pixel & image->blue_mask) >> __builtin_ctzl(image->blue_mask));
    }
  XDestroyImage(image);
  return capture;
}

void send_key(GLFWwindow* window, const std::string& keysym, bool shift, bool control) {
  ::Display* display = glfwGetX11Display();
  const Window x_window = glfwGetX11Window(window);
  const KeySym symbol = XStringToKeysym(keysym.c_str());
  if (symbol == NoSymbol) throw std::runtime_error("send_key: unknown keysym " + keysym);
  const KeyCode code = XKeysymToKeycode(display, symbol);
  if (code == 0) throw std::runtime_error("send_key: no key types " + keysym);
  XKeyEvent event{};
  event.display = display;
  event.window = x_window;
  event.root = DefaultRootWindow(display);
  event.subwindow = None;
  event.time = CurrentTime;
  event.same_screen = True;
  event.keycode = code;
  event.state = (shift ? ShiftMask : 0u) | (control ? ControlMask : 0u);
  for (const int type : {KeyPress, KeyRelease}) {
    event.type = type;
    XSendEvent(display, x_window, True, type == KeyPress ? KeyPressMask : KeyReleaseMask,
               reinterpret_cast<XEvent*>(&event));
  }
  XSync(display, False);
}

}  // namespace nelf::test
