#include "inputs/x11_capture.hpp"

#include <X11/Xatom.h>
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/extensions/XShm.h>
#include <X11/extensions/Xcomposite.h>
#include <X11/extensions/Xdamage.h>
#include <fmt/format.h>
#include <poll.h>
#include <sys/ipc.h>
#include <sys/shm.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <thread>

extern "C" {
#include <libavutil/imgutils.h>
}

#include "core/printable.hpp"
#include "core/user_error.hpp"

namespace nelf {
namespace {

using Clock = std::chrono::steady_clock;

// Xlib's default error handler exits the process; a window that goes away between two requests is
// an ordinary event for a capture. Errors on a capture's connection are recorded for it to check
// (XSync, then the count); errors on any other connection go to the handler that was there before.
std::mutex g_error_mutex;
std::vector<std::pair<::Display*, int*>> g_error_counters;  // connection, errors seen on it
XErrorHandler g_previous_handler = nullptr;

int record_error(::Display* display, XErrorEvent* event) {
  {
    const std::lock_guard lock(g_error_mutex);
    for (auto& [d, count] : g_error_counters)
      if (d == display) {
        ++*count;
        return 0;
      }
  }
  return g_previous_handler ? g_previous_handler(display, event) : 0;
}

struct DisplayCloser {
  void operator()(::Display* d) const { XCloseDisplay(d); }
};
using DisplayPtr = std::unique_ptr<::Display, DisplayCloser>;

std::string window_title(::Display* d, Window w) {
  const Atom net_wm_name = XInternAtom(d, "_NET_WM_NAME", False);
  const Atom utf8 = XInternAtom(d, "UTF8_STRING", False);
  Atom type = None;
  int format = 0;
  unsigned long items = 0, after = 0;
  unsigned char* data = nullptr;
  std::string title;
  if (XGetWindowProperty(d, w, net_wm_name, 0, 1024, False, utf8, &type, &format, &items, &after, &data) == Success &&
      data != nullptr && type == utf8 && format == 8)
    title.assign(reinterpret_cast<const char*>(data), items);
  if (data) XFree(data);
  if (title.empty()) {
    char* name = nullptr;
    if (XFetchName(d, w, &name) && name) title = name;
    if (name) XFree(name);
  }
  return title;
}

std::optional<pid_t> window_pid(::Display* d, Window w) {
  const Atom net_wm_pid = XInternAtom(d, "_NET_WM_PID", False);
  Atom type = None;
  int format = 0;
  unsigned long items = 0, after = 0;
  unsigned char* data = nullptr;
  std::optional<pid_t> pid;
  if (XGetWindowProperty(d, w, net_wm_pid, 0, 1, False, XA_CARDINAL, &type, &format, &items, &after, &data) ==
          Success &&
      data != nullptr && type == XA_CARDINAL && format == 32 && items == 1)
    pid = static_cast<pid_t>(*reinterpret_cast<const unsigned long*>(data));
  if (data) XFree(data);
  return pid;
}

struct WindowInfo {
  Window id = 0;
  std::string title;
  int width = 0, height = 0;
  std::optional<pid_t> pid;
};

// Every mapped InputOutput window below `parent` that the window manager manages, with its title
// and process: override-redirect windows (splash screens, menus, tooltips) are never the game.
void list_windows(::Display* d, Window parent, std::vector<WindowInfo>& out) {
  Window root = 0, up = 0;
  Window* children = nullptr;
  unsigned int n = 0;
  if (!XQueryTree(d, parent, &root, &up, &children, &n)) return;
  const std::vector<Window> kids(children, children + n);
  if (children) XFree(children);
  for (Window w : kids) {
    XWindowAttributes a{};
    if (!XGetWindowAttributes(d, w, &a)) continue;
    if (a.map_state == IsViewable && a.c_class == InputOutput && !a.override_redirect)
      out.push_back({w, window_title(d, w), a.width, a.height, window_pid(d, w)});
    list_windows(d, w, out);
  }
}

std::string describe(const WindowInfo& w) {
  return fmt::format("0x{:x} \"{}\" {}x{}", w.id, printable(w.title), w.width, w.height);
}

// A process that ended (or is a zombie, its windows gone with it) will never open a window.
bool process_alive(pid_t pid) {
  std::ifstream stat(fmt::format("/proc/{}/stat", pid));
  std::string line;
  if (!std::getline(stat, line)) return false;
  const std::size_t close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z';
}

template <typename T>
bool parse_number(std::string_view text, T& value, int base = 10) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value, base);
  return ec == std::errc() && end == text.data() + text.size();
}

bool parse_number(std::string_view text, double& value) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && end == text.data() + text.size();
}

}  // namespace

bool is_x11_capture_spec(std::string_view input) { return input.rfind("x11:", 0) == 0 || input == "x11"; }

X11CaptureSpec parse_x11_capture_spec(const std::string& input) {
  X11CaptureSpec spec;
  bool waits = false;
  std::string_view rest = input == "x11" ? std::string_view() : std::string_view(input).substr(4);
  // A title may hold commas: window= takes the rest of the spec, so it comes last.
  while (!rest.empty()) {
    const std::size_t eq = rest.find('=');
    if (eq == std::string_view::npos)
      throw UserError(fmt::format("{}: expected key=value (window=, window-id=, pid=, display=, fps=, wait=)", input),
                      2);
    const std::string_view key = rest.substr(0, eq);
    std::string_view value;
    if (key == "window") {
      value = rest.substr(eq + 1);
      rest = {};
    } else {
      const std::size_t comma = rest.find(',', eq);
      value = rest.substr(eq + 1, comma == std::string_view::npos ? std::string_view::npos : comma - eq - 1);
      rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
    }
    const auto bad = [&](std::string_view what) {
      return UserError(fmt::format("{}: {}={} is not {}", input, key, value, what), 2);
    };
    if (key == "window") {
      if (value.empty()) throw bad("a title (a part of the window's title)");
      spec.title = std::string(value);
    } else if (key == "window-id") {
      unsigned long id = 0;
      const bool hex = value.rfind("0x", 0) == 0 || value.rfind("0X", 0) == 0;
      if (!parse_number(hex ? value.substr(2) : value, id, hex ? 16 : 10) || id == 0)
        throw bad("a window id (0x1e00002, as xwininfo prints it)");
      spec.window_id = id;
    } else if (key == "pid") {
      pid_t pid = 0;
      if (!parse_number(value, pid) || pid <= 0) throw bad("a process id");
      spec.pid = pid;
    } else if (key == "display") {
      if (value.empty()) throw bad("an X display (:0)");
      spec.display = std::string(value);
    } else if (key == "wait") {
      double wait = 0;
      if (!parse_number(value, wait) || !(wait >= 0 && wait <= 3600)) throw bad("a time from 0 to 3600 seconds");
      spec.wait_s = wait;
      waits = true;
    } else if (key == "fps") {
      double fps = 0;
      if (!parse_number(value, fps) || !(fps >= 1 && fps <= 1000)) throw bad("a rate from 1 to 1000 frames a second");
      spec.fps = fps;
    } else {
      throw UserError(fmt::format("{}: unknown key {} (window=, window-id=, pid=, display=, fps=, wait=)", input, key),
                      2);
    }
  }
  if (int(spec.title.has_value()) + int(spec.window_id.has_value()) + int(spec.pid.has_value()) > 1)
    throw UserError(fmt::format("{}: name the window one way (window=, window-id= or pid=)", input), 2);
  if (spec.pid && !waits) spec.wait_s = 60;  // a game that was just started: its window comes
  return spec;
}

struct X11Capture::State {
  DisplayPtr display;
  int errors = 0;
  Window window = 0;
  bool is_root = false;
  std::string description;
  int damage_event = 0;
  Damage damage = 0;
  Pixmap pixmap = 0;  // the window's off-screen contents (not for the screen)
  int width = 0, height = 0, depth = 0;
  Visual* visual = nullptr;
  bool shm = false;
  XShmSegmentInfo segment{};
  XImage* image = nullptr;
  bool mapped = true, destroyed = false, resized = false, changed = false;
  Clock::time_point last_read{};
  Clock::duration min_interval{};

  ~State() {
    release_image();
    if (display) {
      if (damage) XDamageDestroy(display.get(), damage);
      if (pixmap) XFreePixmap(display.get(), pixmap);
      XSync(display.get(), False);
      const std::lock_guard lock(g_error_mutex);
      std::erase_if(g_error_counters, [&](const auto& e) { return e.first == display.get(); });
    }
  }

  void release_image() {
    if (!image) return;
    if (shm) {
      XShmDetach(display.get(), &segment);
      XSync(display.get(), False);
      shmdt(segment.shmaddr);
      image->data = nullptr;  // shared memory, not Xlib's to free
    }
    XDestroyImage(image);
    image = nullptr;
  }

  // The pixmap (windows) and image of the current size.
  void prepare() {
    release_image();
    if (!is_root) {
      if (pixmap) XFreePixmap(display.get(), pixmap);
      pixmap = XCompositeNameWindowPixmap(display.get(), window);
    }
    XWindowAttributes a{};
    if (!XGetWindowAttributes(display.get(), window, &a)) {
      destroyed = true;
      return;
    }
    width = a.width;
    height = a.height;
    depth = a.depth;
    visual = a.visual;
    if (shm) {
      image = XShmCreateImage(display.get(), visual, static_cast<unsigned>(depth), ZPixmap, nullptr, &segment,
                              static_cast<unsigned>(width), static_cast<unsigned>(height));
      if (!image) throw UserError(fmt::format("x11: cannot make a shared image of {}", description), 1);
      segment.shmid =
          shmget(IPC_PRIVATE, static_cast<std::size_t>(image->bytes_per_line) * image->height, IPC_CREAT | 0600);
      if (segment.shmid < 0) {
        XDestroyImage(image);
        image = nullptr;
        throw UserError(fmt::format("x11: no shared memory for {}: {}", description, std::strerror(errno)), 1);
      }
      segment.shmaddr = image->data = static_cast<char*>(shmat(segment.shmid, nullptr, 0));
      segment.readOnly = False;
      XShmAttach(display.get(), &segment);
      XSync(display.get(), False);
      shmctl(segment.shmid, IPC_RMID, nullptr);  // gone once both sides detach
    }
    resized = false;
  }

  void handle_events() {
    while (XPending(display.get()) > 0) {
      XEvent event;
      XNextEvent(display.get(), &event);
      if (event.type == damage_event + XDamageNotify) {
        changed = true;
      } else if (event.type == ConfigureNotify && event.xconfigure.window == window) {
        if (event.xconfigure.width != width || event.xconfigure.height != height) resized = changed = true;
      } else if (event.type == DestroyNotify && event.xdestroywindow.window == window) {
        destroyed = true;
      } else if (event.type == UnmapNotify && event.xunmap.window == window) {
        mapped = false;
      } else if (event.type == MapNotify && event.xmap.window == window) {
        mapped = true;
        resized = changed = true;  // a mapped window has a new pixmap
      }
    }
  }

  CapturedImage read_now() {
    // The notices of changes so far (all queued once XSync returns) are for what this read shows:
    // dropped. The damage is emptied again just before the read, without looking: Damage notices
    // only when it goes from empty to not, so a change between the two would otherwise leave it
    // full, and no change after would ever be noticed.
    XDamageSubtract(display.get(), damage, None, None);
    XSync(display.get(), False);
    handle_events();
    changed = false;
    if (resized) prepare();
    XDamageSubtract(display.get(), damage, None, None);
    const Drawable drawable = is_root ? window : pixmap;
    const int errors_before = errors;
    XImage* got = nullptr;
    if (shm) {
      if (XShmGetImage(display.get(), drawable, image, 0, 0, AllPlanes)) got = image;
    } else {
      got = XGetImage(display.get(), drawable, 0, 0, static_cast<unsigned>(width), static_cast<unsigned>(height),
                      AllPlanes, ZPixmap);
    }
    XSync(display.get(), False);
    if (!got || errors != errors_before) {
      handle_events();
      if (!destroyed) resized = true;  // read again at the new size
      if (got && got != image) XDestroyImage(got);
      return {};
    }
    CapturedImage out = convert(*got);
    if (got != image) XDestroyImage(got);
    out.captured_at = Clock::now();
    last_read = out.captured_at;
    return out;
  }

  CapturedImage convert(const XImage& im) const {
    // The masks are the visual's (a pixmap's image may leave its own unset).
    if (im.bits_per_pixel != 32 || visual->red_mask != 0xff0000 || visual->green_mask != 0xff00 ||
        visual->blue_mask != 0xff || im.byte_order != LSBFirst)
      throw UserError(fmt::format("x11: {} has {}-bit pixels nelf cannot read (it reads 24- and 32-bit true colour; "
                                  "masks {:x} {:x} {:x}, order {})",
                                  description, im.bits_per_pixel, visual->red_mask, visual->green_mask,
                                  visual->blue_mask, im.byte_order),
                      1);
    // Kept as the server keeps them (B G R X in memory): the block means are reordered instead,
    // a quarter or less of the bytes (rgba8_block_means), where swapping every pixel here took
    // milliseconds a frame waits to be shown.
    CapturedImage out;
    out.width = im.width;
    out.height = im.height;
    out.order = ByteOrder::bgrx;
    const int row = im.width * 4;
    out.pixels.resize(static_cast<std::size_t>(row) * im.height);
    av_image_copy_plane(out.pixels.data(), row, reinterpret_cast<const std::uint8_t*>(im.data), im.bytes_per_line, row,
                        im.height);
    return out;
  }
};

X11Capture::X11Capture(const X11CaptureSpec& spec, const std::atomic<bool>* stop) : state_(std::make_unique<State>()) {
  State& s = *state_;
  const char* env = std::getenv("DISPLAY");
  const std::string name = !spec.display.empty() ? spec.display : env ? env : "";
  if (name.empty()) throw UserError("x11: no X display (DISPLAY is not set; or pass x11:display=:0)", 1);
  s.display.reset(XOpenDisplay(name.c_str()));
  if (!s.display) throw UserError(fmt::format("x11: cannot open display {}", printable(name)), 1);
  ::Display* d = s.display.get();
  {
    const std::lock_guard lock(g_error_mutex);
    const XErrorHandler previous = XSetErrorHandler(record_error);
    if (previous != record_error) g_previous_handler = previous;
    g_error_counters.emplace_back(d, &s.errors);
  }
  int event_base = 0, error_base = 0, major = 0, minor = 0;
  if (!XCompositeQueryExtension(d, &event_base, &error_base) ||
      (XCompositeQueryVersion(d, &major, &minor), major == 0 && minor < 2))
    throw UserError(fmt::format("x11: display {} has no Composite extension 0.2 (needed to read a window)", name), 1);
  if (!XDamageQueryExtension(d, &s.damage_event, &error_base))
    throw UserError(fmt::format("x11: display {} has no Damage extension (needed to see a window change)", name), 1);
  Bool pixmaps = False;
  s.shm = XShmQueryVersion(d, &major, &minor, &pixmaps) != 0;

  const Window root = DefaultRootWindow(d);
  if (spec.window_id) {
    XWindowAttributes a{};
    XSync(d, False);
    const int before = s.errors;
    const bool ok = XGetWindowAttributes(d, *spec.window_id, &a) != 0;
    XSync(d, False);
    if (!ok || s.errors != before)
      throw UserError(fmt::format("x11: no window 0x{:x} on display {} (xwininfo lists them)", *spec.window_id, name),
                      1);
    s.window = *spec.window_id;
    s.description = fmt::format("window 0x{:x} \"{}\"", s.window, printable(window_title(d, s.window)));
  } else if (spec.title || spec.pid) {
    const Clock::time_point give_up =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(spec.wait_s));
    for (;;) {
      std::vector<WindowInfo> all, found;
      list_windows(d, root, all);
      for (const WindowInfo& w : all)
        if (spec.title ? w.title.find(*spec.title) != std::string::npos : w.pid == spec.pid) found.push_back(w);
      if (spec.pid && found.size() > 1) {  // a process's helper windows: its largest is the game
        std::sort(found.begin(), found.end(),
                  [](const WindowInfo& a, const WindowInfo& b) { return a.width * a.height > b.width * b.height; });
        found.resize(1);
      }
      if (found.size() > 1) {
        std::string list;
        for (const WindowInfo& w : found) list += (list.empty() ? "" : ", ") + describe(w);
        throw UserError(fmt::format("x11:window={} matches {} windows: {}; name one with x11:window-id=",
                                    printable(*spec.title), found.size(), list),
                        2);
      }
      if (found.size() == 1) {
        s.window = found[0].id;
        s.description = fmt::format("window 0x{:x} \"{}\"", s.window, printable(found[0].title));
        break;
      }
      if (stop && stop->load()) throw UserError("interrupted while waiting for the window", 130);
      if (spec.pid && !process_alive(*spec.pid))
        throw UserError(fmt::format("x11: process {} ended without opening a window", *spec.pid), 1);
      if (Clock::now() >= give_up)
        throw UserError(spec.title ? fmt::format("x11: no window on display {} has \"{}\" in its title", name,
                                                 printable(*spec.title))
                                   : fmt::format("x11: process {} opened no window in {:g} s", *spec.pid, spec.wait_s),
                        1);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  } else {
    s.window = root;
    s.is_root = true;
    s.description = fmt::format("the screen of {}", printable(name));
  }
  s.min_interval = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / spec.fps));
  if (!s.is_root) {
    XSelectInput(d, s.window, StructureNotifyMask);
    XCompositeRedirectWindow(d, s.window, CompositeRedirectAutomatic);
  }
  s.damage = XDamageCreate(d, s.window, XDamageReportNonEmpty);
  XSync(d, False);
  s.prepare();
  XSync(d, False);
  if (s.destroyed) throw UserError(fmt::format("x11: {} closed while opening it", s.description), 1);
}

X11Capture::~X11Capture() = default;

CapturedImage X11Capture::read() {
  for (int attempt = 0; attempt < 3; ++attempt) {
    CapturedImage image = state_->read_now();
    if (image.width > 0) return image;
    if (state_->destroyed) break;
  }
  throw UserError(fmt::format("x11: cannot read {}", state_->description), 1);
}

std::optional<CapturedImage> X11Capture::read_when_changed(std::chrono::milliseconds wait) {
  State& s = *state_;
  const Clock::time_point until = Clock::now() + wait;
  for (;;) {
    s.handle_events();
    if (s.destroyed) return std::nullopt;
    const Clock::time_point now = Clock::now();
    if (s.changed && s.mapped) {
      // At most fps reads a second: a change sooner waits for its turn (it is read then, newest).
      const Clock::time_point turn = s.last_read + s.min_interval;
      if (now >= turn) {
        CapturedImage image = s.read_now();
        if (image.width > 0) return image;
        continue;
      }
      if (turn > until) return std::nullopt;
      std::this_thread::sleep_until(turn);
      continue;
    }
    if (now >= until) return std::nullopt;
    pollfd fd{ConnectionNumber(s.display.get()), POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - now).count();
    ::poll(&fd, 1, static_cast<int>(std::max<long long>(1, left)));
  }
}

bool X11Capture::closed() const { return state_->destroyed; }

const std::string& X11Capture::description() const { return state_->description; }

}  // namespace nelf
