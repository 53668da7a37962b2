// Swap control (GLX_EXT_swap_control, GLX_MESA_swap_control, GLX_SGI_swap_control) against nelf's
// display, offered whether or not the driver has it (Mesa on Xvfb has none): the interval the game
// asked for, 1 until it asks (GLX's default). glXSwapBuffers (nelf_glx_stereo.cpp) returns by it.
#include <time.h>

#include <atomic>
#include <cerrno>
#include <map>
#include <string>
#include <string_view>
#include <utility>

#include "inputs/glx_interposer/interposed_gl.hpp"

namespace nelf::glx_interposer {

namespace {

std::atomic<int> g_swap_interval{1};
constexpr const char* kSwapControl[] = {"GLX_EXT_swap_control", "GLX_MESA_swap_control", "GLX_SGI_swap_control"};

bool lists(const char* extensions, std::string_view name) {
  const std::string_view all = extensions ? extensions : "";
  for (std::size_t at = all.find(name); at != std::string_view::npos; at = all.find(name, at + 1)) {
    const std::size_t end = at + name.size();
    if ((at == 0 || all[at - 1] == ' ') && (end == all.size() || all[end] == ' ')) return true;
  }
  return false;
}

// The game's interval, kept for glXSwapBuffers and given to the driver, except for a window whose
// swaps nelf's refreshes pace (the driver's vsync to the desktop's monitor would add its own wait).
void set_swap_interval(Display* dpy, GLXDrawable drawable, int interval) {
  g_swap_interval = interval;
  const Eyes* e = t_current;
  driver_swap_interval(dpy, drawable, e && e->window_unpaced ? 0 : interval);
}

}  // namespace

int swap_interval() { return g_swap_interval.load(); }

// The driver's own swap interval for the game's window, where the driver has swap control.
void driver_swap_interval(Display* dpy, GLXDrawable drawable, int interval) {
  NELF_REAL_GLX(glXQueryExtensionsString);
  NELF_REAL_GLX(glXGetCurrentDisplay);
  if (!dpy) dpy = real_glXGetCurrentDisplay();
  if (!dpy || !real_glXQueryExtensionsString) return;
  const char* extensions = real_glXQueryExtensionsString(dpy, DefaultScreen(dpy));
  using Ext = void (*)(Display*, GLXDrawable, int);
  using Mesa = int (*)(unsigned int);
  using Sgi = int (*)(int);
  if (lists(extensions, kSwapControl[0]) && drawable) {
    if (const auto f = real_gl<Ext>("glXSwapIntervalEXT")) f(dpy, drawable, interval);
  } else if (lists(extensions, kSwapControl[1])) {
    if (const auto f = real_gl<Mesa>("glXSwapIntervalMESA")) f(static_cast<unsigned int>(interval));
  } else if (lists(extensions, kSwapControl[2]) && interval > 0) {
    if (const auto f = real_gl<Sgi>("glXSwapIntervalSGI")) f(interval);
  }
}

void sleep_until_ns(std::int64_t t) {
  timespec ts{static_cast<time_t>(t / 1000000000LL), static_cast<long>(t % 1000000000LL)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace nelf::glx_interposer

using namespace nelf::glx_interposer;

extern "C" {

__attribute__((visibility("default"))) void glXSwapIntervalEXT(Display* dpy, GLXDrawable drawable, int interval) {
  set_swap_interval(dpy, drawable, interval < 0 ? -interval : interval);  // < 0: adaptive, as vsync here
}

__attribute__((visibility("default"))) int glXSwapIntervalMESA(unsigned int interval) {
  set_swap_interval(nullptr, 0, static_cast<int>(interval));
  return 0;
}

__attribute__((visibility("default"))) int glXSwapIntervalSGI(int interval) {
  if (interval <= 0) return GLX_BAD_VALUE;
  set_swap_interval(nullptr, 0, interval);
  return 0;
}

__attribute__((visibility("default"))) int glXGetSwapIntervalMESA() { return g_swap_interval.load(); }

__attribute__((visibility("default"))) void glXQueryDrawable(Display* dpy, GLXDrawable drawable, int attribute,
                                                             unsigned int* value) {
  NELF_REAL_GLX(glXQueryDrawable);
  if (attribute == GLX_SWAP_INTERVAL_EXT)
    *value = static_cast<unsigned int>(g_swap_interval.load());
  else if (attribute == GLX_MAX_SWAP_INTERVAL_EXT)
    *value = 8;
  else if (real_glXQueryDrawable)
    real_glXQueryDrawable(dpy, drawable, attribute, value);
}

// The driver's extensions and swap control.
__attribute__((visibility("default"))) const char* glXQueryExtensionsString(Display* dpy, int screen) {
  NELF_REAL_GLX(glXQueryExtensionsString);
  const char* real = real_glXQueryExtensionsString ? real_glXQueryExtensionsString(dpy, screen) : nullptr;
  std::lock_guard lock(g_mutex);
  static std::map<std::pair<Display*, int>, std::string> answers;  // nodes stay put: the pointers hold
  std::string& answer = answers[{dpy, screen}];
  if (answer.empty()) {
    answer = real ? real : "";
    for (const char* name : kSwapControl)
      if (!lists(real, name)) answer += answer.empty() ? std::string(name) : " " + std::string(name);
  }
  return answer.c_str();
}

}  // extern "C"
