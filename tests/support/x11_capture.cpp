#include "support/x11_capture.hpp"

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

}  // namespace nelf::test
