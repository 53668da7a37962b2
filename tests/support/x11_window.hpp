#pragma once
// Test access to a GLFW window's X11 side: what it shows and synthetic key presses.
#include <string>

// What an X11 window shows, read from the X server (XGetImage): the pixels a user would see, whatever
// the GL driver does with its front buffer (Mesa's software GLX on Xvfb reads its front buffer as
// black; the window itself holds the swapped image).
#include <array>
#include <vector>

struct GLFWwindow;

namespace nelf::test {

struct WindowCapture {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;  // row 0 = the window's top row
  std::array<int, 3> at(int x, int y) const {
    const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

// Waits for the X server to have drawn everything sent so far (XSync), then reads the window.
// Throws std::runtime_error when the window cannot be read (e.g. not mapped).
WindowCapture capture_window(GLFWwindow* window);

// Sends a key press and release of `keysym` (an X keysym name: "plus", "bracketleft", "s", "Left",
// "space", "Escape") to the window, as the X server would for a user typing it; with Shift held
// when `shift`. The window sees it on its next event poll.
void send_key(GLFWwindow* window, const std::string& keysym, bool shift = false, bool control = false);

}  // namespace nelf::test
