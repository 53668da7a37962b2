#include "inputs/screencast_portal.hpp"

#include <fcntl.h>
#include <systemd/sd-bus.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>

#include <fmt/format.h>

#include "core/printable.hpp"
#include "core/state_files.hpp"
#include "core/user_error.hpp"

namespace nelf {
namespace {

// sd-bus (libsystemd) is the D-Bus client: a small, well-kept C library already on every Debian
// desktop, whose variadic append writes the portal's a{sv} option dictionaries in one call.
constexpr const char* kPortal = "org.freedesktop.portal.Desktop";
constexpr const char* kPortalPath = "/org/freedesktop/portal/desktop";
constexpr const char* kScreenCast = "org.freedesktop.portal.ScreenCast";

// The portal's source types and cursor modes (bit masks in its properties).
constexpr std::uint32_t kMonitor = 1, kWindow = 2;
constexpr std::uint32_t kCursorHidden = 1;
constexpr std::uint32_t kPersistUntilRevoked = 2;

struct BusDeleter {
  void operator()(sd_bus* bus) const { sd_bus_flush_close_unref(bus); }
};
struct MessageDeleter {
  void operator()(sd_bus_message* m) const { sd_bus_message_unref(m); }
};
struct SlotDeleter {
  void operator()(sd_bus_slot* slot) const { sd_bus_slot_unref(slot); }
};
using Message = std::unique_ptr<sd_bus_message, MessageDeleter>;

struct BusError {
  sd_bus_error error = SD_BUS_ERROR_NULL;
  BusError() = default;
  BusError(const BusError&) = delete;
  BusError& operator=(const BusError&) = delete;
  ~BusError() { sd_bus_error_free(&error); }
  std::string text(int r) const {
    return error.message ? std::string(error.message) : std::string(std::strerror(r < 0 ? -r : EIO));
  }
};

// Reads the a{sv} at the message's position, calling `entry(key)` with the message at the variant;
// an entry it does not read (returns false) is skipped.
int read_options(sd_bus_message* m, const std::function<bool(std::string_view)>& entry) {
  int r = sd_bus_message_enter_container(m, 'a', "{sv}");
  if (r < 0) return r;
  while ((r = sd_bus_message_enter_container(m, 'e', "sv")) > 0) {
    const char* key = nullptr;
    if ((r = sd_bus_message_read(m, "s", &key)) < 0) return r;
    if (!entry(key) && (r = sd_bus_message_skip(m, "v")) < 0) return r;
    if ((r = sd_bus_message_exit_container(m)) < 0) return r;
  }
  if (r < 0) return r;
  return sd_bus_message_exit_container(m);
}

// Where the restore token is kept: $XDG_STATE_HOME/nelf/screencast-restore-token; empty (nothing
// kept, the user is asked each time) without a state folder.
std::filesystem::path restore_token_path() {
  const std::filesystem::path home = xdg_state_home();
  return home.empty() ? home : home / "nelf" / "screencast-restore-token";
}

}  // namespace

struct ScreenCastPortal::State {
  std::string input;
  const std::atomic<bool>* stop = nullptr;
  std::unique_ptr<sd_bus, BusDeleter> bus;
  std::string sender;   // the unique name, as the portal spells it in request paths ("1_42")
  std::string session;  // the session's object path, closed with the object
  unsigned requests = 0;
  unsigned node = 0;
  std::string source_type;
  UniqueFd pipewire;

  State() = default;
  State(const State&) = delete;
  State& operator=(const State&) = delete;
  // Closing the session ends the cast, also when opening it failed half-way.
  ~State() {
    if (bus && !session.empty())
      sd_bus_call_method(bus.get(), kPortal, session.c_str(), "org.freedesktop.portal.Session", "Close", nullptr,
                         nullptr, "");
  }

  [[noreturn]] void fail(const std::string& why, int status = 1) const {
    throw UserError(fmt::format("{}: {}", printable(input), why), status);
  }

  // One portal request: calls `method` with the arguments `append` writes (ending with an options
  // dictionary that receives the handle token), waits for the request's Response signal and returns
  // its results, the message positioned at the a{sv}; the response code in `code`.
  Message request(const char* method, const std::function<void(sd_bus_message*, const std::string&)>& append,
                  std::uint32_t& code) {
    const std::string token = fmt::format("nelf{}_{}", getpid(), ++requests);
    const std::string path = fmt::format("{}/request/{}/{}", kPortalPath, sender, token);
    struct Pending {
      bool done = false;
      std::uint32_t code = 2;
      Message results;
    } pending;
    const auto on_response = [](sd_bus_message* m, void* data, sd_bus_error*) -> int {
      auto* p = static_cast<Pending*>(data);
      if (sd_bus_message_read(m, "u", &p->code) < 0) p->code = 2;
      p->results.reset(sd_bus_message_ref(m));
      p->done = true;
      return 0;
    };
    sd_bus_slot* raw_slot = nullptr;
    int r = sd_bus_match_signal(bus.get(), &raw_slot, nullptr, path.c_str(), "org.freedesktop.portal.Request",
                                "Response", on_response, &pending);
    if (r < 0) fail(fmt::format("cannot listen to the ScreenCast portal ({})", std::strerror(-r)));
    const std::unique_ptr<sd_bus_slot, SlotDeleter> slot(raw_slot);

    sd_bus_message* raw_call = nullptr;
    r = sd_bus_message_new_method_call(bus.get(), &raw_call, kPortal, kPortalPath, kScreenCast, method);
    if (r < 0) fail(fmt::format("cannot call the ScreenCast portal ({})", std::strerror(-r)));
    const Message call(raw_call);
    append(call.get(), token);
    BusError error;
    sd_bus_message* raw_reply = nullptr;
    r = sd_bus_call(bus.get(), call.get(), 30'000'000, &error.error, &raw_reply);
    const Message reply(raw_reply);
    if (r < 0) fail(fmt::format("the ScreenCast portal refused {} ({})", method, error.text(r)));
    const char* handle = nullptr;
    if (sd_bus_message_read(reply.get(), "o", &handle) < 0 || !handle)
      fail(fmt::format("the ScreenCast portal answered {} without a request", method));
    // Portals older than 0.9 chose the request's path themselves: listen there too.
    std::unique_ptr<sd_bus_slot, SlotDeleter> other_slot;
    if (path != handle) {
      sd_bus_slot* raw_other = nullptr;
      if (sd_bus_match_signal(bus.get(), &raw_other, nullptr, handle, "org.freedesktop.portal.Request", "Response",
                              on_response, &pending) >= 0)
        other_slot.reset(raw_other);
    }
    const std::string request_path = handle;

    // The Start request waits on the user's choice in the desktop's dialog: no deadline but Ctrl-C.
    while (!pending.done) {
      if (stop && *stop) {
        sd_bus_call_method(bus.get(), kPortal, request_path.c_str(), "org.freedesktop.portal.Request", "Close", nullptr,
                           nullptr, "");
        fail("interrupted", 130);
      }
      r = sd_bus_process(bus.get(), nullptr);
      if (r < 0)
        fail(fmt::format("lost the session bus while waiting for the ScreenCast portal ({})", std::strerror(-r)));
      if (r > 0) continue;
      r = sd_bus_wait(bus.get(), 100'000);
      if (r < 0 && r != -EINTR)
        fail(fmt::format("lost the session bus while waiting for the ScreenCast portal ({})", std::strerror(-r)));
    }
    code = pending.code;
    return std::move(pending.results);
  }

  std::uint32_t property(const char* name, std::uint32_t fallback) {
    BusError error;
    std::uint32_t value = 0;
    return sd_bus_get_property_trivial(bus.get(), kPortal, kPortalPath, kScreenCast, name, &error.error, 'u', &value) <
                   0
               ? fallback
               : value;
  }

  // A choice that cannot be kept only means the user is asked again next time.
  static void save_restore_token(const std::string& token) {
    if (const auto path = restore_token_path(); !path.empty()) replace_file(path, token + "\n", 0600);
  }

  static std::string kept_restore_token() {
    const auto path = restore_token_path();
    if (path.empty()) return {};
    std::ifstream file(path);
    std::string token;
    std::getline(file, token);
    return token;
  }
};

ScreenCastPortal::ScreenCastPortal(const ScreenCastPortalOptions& options, const std::string& input,
                                   const std::atomic<bool>* stop)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.input = input;
  s.stop = stop;

  sd_bus* raw_bus = nullptr;
  int r = sd_bus_open_user(&raw_bus);
  s.bus.reset(raw_bus);
  if (r < 0)
    s.fail(
        fmt::format("cannot reach the session bus ({}); pipewire: asks the desktop's ScreenCast portal, which "
                    "lives on a desktop session's bus (or name a node: pipewire:node=ID)",
                    std::strerror(-r)));
  const char* unique = nullptr;
  if ((r = sd_bus_get_unique_name(s.bus.get(), &unique)) < 0 || !unique)
    s.fail(fmt::format("cannot reach the session bus ({})", std::strerror(r < 0 ? -r : EIO)));
  s.sender = unique[0] == ':' ? unique + 1 : unique;
  for (char& c : s.sender)
    if (c == '.') c = '_';

  BusError error;
  std::uint32_t version = 0;
  r = sd_bus_get_property_trivial(s.bus.get(), kPortal, kPortalPath, kScreenCast, "version", &error.error, 'u',
                                  &version);
  if (r < 0)
    s.fail(
        fmt::format("no ScreenCast portal on the session bus ({}); install xdg-desktop-portal and the "
                    "desktop's backend (xdg-desktop-portal-gnome, -kde or -wlr), or name a node: "
                    "pipewire:node=ID",
                    error.text(r)));
  const std::uint32_t types = s.property("AvailableSourceTypes", kMonitor) & (kMonitor | kWindow);
  const std::uint32_t cursors = version >= 2 ? s.property("AvailableCursorModes", 0) : 0;
  const std::string kept = options.restore && version >= 4 ? State::kept_restore_token() : std::string();

  // CreateSession → SelectSources → Start → OpenPipeWireRemote, as every screen-casting client does.
  std::uint32_t code = 2;
  Message results = s.request(
      "CreateSession",
      [&](sd_bus_message* m, const std::string& token) {
        sd_bus_message_append(m, "a{sv}", 2, "handle_token", "s", token.c_str(), "session_handle_token", "s",
                              token.c_str());
      },
      code);
  if (code != 0) s.fail("the ScreenCast portal did not open a session");
  read_options(results.get(), [&](std::string_view key) {
    const char* handle = nullptr;
    if (key != "session_handle" || sd_bus_message_read(results.get(), "v", "s", &handle) < 0 || !handle) return false;
    s.session = handle;
    return true;
  });
  if (s.session.empty()) s.fail("the ScreenCast portal opened a session without naming it");

  results = s.request(
      "SelectSources",
      [&](sd_bus_message* m, const std::string& token) {
        sd_bus_message_append(m, "o", s.session.c_str());
        sd_bus_message_open_container(m, 'a', "{sv}");
        sd_bus_message_append(m, "{sv}", "handle_token", "s", token.c_str());
        sd_bus_message_append(m, "{sv}", "types", "u", types ? types : kMonitor);
        sd_bus_message_append(m, "{sv}", "multiple", "b", 0);
        if (cursors & kCursorHidden) sd_bus_message_append(m, "{sv}", "cursor_mode", "u", kCursorHidden);
        if (version >= 4) {
          sd_bus_message_append(m, "{sv}", "persist_mode", "u", kPersistUntilRevoked);
          if (!kept.empty()) sd_bus_message_append(m, "{sv}", "restore_token", "s", kept.c_str());
        }
        sd_bus_message_close_container(m);
      },
      code);
  if (code == 1) s.fail("the screen cast was cancelled");
  if (code != 0) s.fail("the ScreenCast portal refused the sources nelf asked for (a monitor or a window)");

  results = s.request(
      "Start",
      [&](sd_bus_message* m, const std::string& token) {
        sd_bus_message_append(m, "os", s.session.c_str(), "");
        sd_bus_message_append(m, "a{sv}", 1, "handle_token", "s", token.c_str());
      },
      code);
  if (code == 1) s.fail("the screen cast was cancelled in the desktop's dialog");
  if (code != 0) s.fail("the ScreenCast portal could not start the screen cast");
  bool have_stream = false;
  std::string restore_token;
  read_options(results.get(), [&](std::string_view key) {
    sd_bus_message* m = results.get();
    if (key == "restore_token") {
      const char* token = nullptr;
      if (sd_bus_message_read(m, "v", "s", &token) < 0 || !token) return false;
      restore_token = token;
      return true;
    }
    if (key != "streams" || sd_bus_message_enter_container(m, 'v', "a(ua{sv})") < 0) return false;
    sd_bus_message_enter_container(m, 'a', "(ua{sv})");
    while (sd_bus_message_enter_container(m, 'r', "ua{sv}") > 0) {
      std::uint32_t node = 0;
      sd_bus_message_read(m, "u", &node);
      std::uint32_t type = 0;
      read_options(m, [&](std::string_view property) {
        return property == "source_type" && sd_bus_message_read(m, "v", "u", &type) >= 0;
      });
      sd_bus_message_exit_container(m);
      if (!have_stream) {
        have_stream = true;
        s.node = node;
        s.source_type = type == kMonitor ? "monitor" : type == kWindow ? "window" : "";
      }
    }
    sd_bus_message_exit_container(m);
    sd_bus_message_exit_container(m);
    return true;
  });
  if (!have_stream) s.fail("the ScreenCast portal started a screen cast without a stream");
  if (!restore_token.empty()) s.save_restore_token(restore_token);

  sd_bus_message* raw_reply = nullptr;
  BusError remote_error;
  r = sd_bus_call_method(s.bus.get(), kPortal, kPortalPath, kScreenCast, "OpenPipeWireRemote", &remote_error.error,
                         &raw_reply, "oa{sv}", s.session.c_str(), 0);
  const Message reply(raw_reply);
  int fd = -1;
  if (r < 0 || sd_bus_message_read(reply.get(), "h", &fd) < 0 || fd < 0)
    s.fail(fmt::format("the ScreenCast portal did not open PipeWire for the cast ({})", remote_error.text(r)));
  s.pipewire = UniqueFd(fcntl(fd, F_DUPFD_CLOEXEC, 3));  // the message owns its fd
  if (s.pipewire.get() < 0) s.fail(fmt::format("cannot keep PipeWire's connection ({})", std::strerror(errno)));
}

ScreenCastPortal::~ScreenCastPortal() = default;

unsigned ScreenCastPortal::node_id() const { return state_->node; }

const std::string& ScreenCastPortal::source_type() const { return state_->source_type; }

UniqueFd ScreenCastPortal::take_pipewire_fd() { return std::move(state_->pipewire); }

}  // namespace nelf
