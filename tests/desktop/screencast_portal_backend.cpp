// The desktop's half of the ScreenCast portal, for the tests of `pipewire:` alone: what GNOME's,
// KDE's and wlroots' backends do behind xdg-desktop-portal, with the user's answer given on the
// command line instead of a dialog. Debian 12's real backends need a GPU here (xdg-desktop-portal-wlr
// 0.7.0 refuses to cast unless the compositor's screencopy offers DMA-BUF, which sway's software
// renderer does not; GNOME's and KDE's dialogs need a person), so the tests run the real front end,
// /usr/libexec/xdg-desktop-portal — the token store, the PipeWire connection restricted to the cast's
// node — against this backend, and a real PipeWire node as the screen.
//
//   nelf-test-screencast-backend --node-file FILE --width W --height H --answer accept|cancel|never
//                                --log FILE
//
// It owns org.freedesktop.impl.portal.desktop.nelftest. Each cast is of the PipeWire node whose id
// the node file holds when the cast starts (a desktop makes a node per cast). `never` leaves the
// dialog open for good. One line per event goes to the log: `asked` (the user would have been shown
// the chooser), `restored` (restore data came back, no dialog), `cancelled`, `started`, `closed`;
// LOG.ready appears once the backend is on the bus.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <systemd/sd-bus.h>
#pragma GCC diagnostic pop

#include <signal.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

namespace {

struct Config {
  std::string node_file;
  std::int32_t width = 0, height = 0;
  std::string answer = "accept";
  std::string log;
  std::uint32_t persist_mode = 0;  // what the last SelectSources asked for
};
Config config;
volatile sig_atomic_t stopping = 0;

void log_event(const char* event) { std::ofstream(config.log, std::ios::app) << event << '\n'; }

struct BusDeleter {
  void operator()(sd_bus* bus) const { sd_bus_flush_close_unref(bus); }
};
struct SlotDeleter {
  void operator()(sd_bus_slot* slot) const { sd_bus_slot_unref(slot); }
};

int close_session(sd_bus_message* m, void*, sd_bus_error*) {
  log_event("closed");
  return sd_bus_reply_method_return(m, "");
}

// sd-bus's vtable macros are C designated initialisers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const sd_bus_vtable kSessionVtable[] = {SD_BUS_VTABLE_START(0),
                                        SD_BUS_METHOD("Close", "", "", close_session, SD_BUS_VTABLE_UNPRIVILEGED),
                                        SD_BUS_SIGNAL("Closed", "", 0), SD_BUS_VTABLE_END};
#pragma GCC diagnostic pop

std::unique_ptr<sd_bus_slot, SlotDeleter> session_slot;
std::unique_ptr<sd_bus_message, decltype(&sd_bus_message_unref)> pending_dialog(nullptr, sd_bus_message_unref);

int create_session(sd_bus_message* m, void*, sd_bus_error*) {
  const char *handle = nullptr, *session = nullptr, *app = nullptr;
  int r = sd_bus_message_read(m, "oos", &handle, &session, &app);
  if (r < 0) return r;
  sd_bus_slot* slot = nullptr;
  r = sd_bus_add_object_vtable(sd_bus_message_get_bus(m), &slot, session, "org.freedesktop.impl.portal.Session",
                               kSessionVtable, nullptr);
  if (r < 0) return r;
  session_slot.reset(slot);
  return sd_bus_reply_method_return(m, "ua{sv}", 0u, 0);
}

int select_sources(sd_bus_message* m, void*, sd_bus_error*) {
  const char *handle = nullptr, *session = nullptr, *app = nullptr;
  int r = sd_bus_message_read(m, "oos", &handle, &session, &app);
  if (r < 0) return r;
  bool restored = false;
  config.persist_mode = 0;
  if ((r = sd_bus_message_enter_container(m, 'a', "{sv}")) < 0) return r;
  while ((r = sd_bus_message_enter_container(m, 'e', "sv")) > 0) {
    const char* key = nullptr;
    if ((r = sd_bus_message_read(m, "s", &key)) < 0) return r;
    if (std::strcmp(key, "persist_mode") == 0) {
      if ((r = sd_bus_message_read(m, "v", "u", &config.persist_mode)) < 0) return r;
    } else if (std::strcmp(key, "restore_data") == 0) {
      const char* vendor = nullptr;
      std::uint32_t version = 0;
      if ((r = sd_bus_message_enter_container(m, 'v', "(suv)")) < 0) return r;
      if ((r = sd_bus_message_enter_container(m, 'r', "suv")) < 0) return r;
      if ((r = sd_bus_message_read(m, "su", &vendor, &version)) < 0) return r;
      restored = std::strcmp(vendor, "nelf-test") == 0 && version == 1;
      if ((r = sd_bus_message_skip(m, "v")) < 0) return r;
      sd_bus_message_exit_container(m);
      sd_bus_message_exit_container(m);
    } else if ((r = sd_bus_message_skip(m, "v")) < 0) {
      return r;
    }
    sd_bus_message_exit_container(m);
  }
  log_event(restored ? "restored" : "asked");
  if (!restored && config.answer == "never") {
    // The dialog stays open: the request is answered by nothing until the client gives up.
    pending_dialog.reset(sd_bus_message_ref(m));
    return 1;
  }
  if (!restored && config.answer != "accept") {
    log_event("cancelled");
    return sd_bus_reply_method_return(m, "ua{sv}", 1u, 0);
  }
  return sd_bus_reply_method_return(m, "ua{sv}", 0u, 0);
}

int start(sd_bus_message* m, void*, sd_bus_error*) {
  const char *handle = nullptr, *session = nullptr, *app = nullptr, *parent = nullptr;
  int r = sd_bus_message_read(m, "ooss", &handle, &session, &app, &parent);
  if (r < 0) return r;
  sd_bus_message* reply = nullptr;
  if ((r = sd_bus_message_new_method_return(m, &reply)) < 0) return r;
  const std::unique_ptr<sd_bus_message, decltype(&sd_bus_message_unref)> owned(reply, sd_bus_message_unref);
  sd_bus_message_append(reply, "u", 0u);
  sd_bus_message_open_container(reply, 'a', "{sv}");
  sd_bus_message_open_container(reply, 'e', "sv");
  sd_bus_message_append(reply, "s", "streams");
  sd_bus_message_open_container(reply, 'v', "a(ua{sv})");
  sd_bus_message_open_container(reply, 'a', "(ua{sv})");
  sd_bus_message_open_container(reply, 'r', "ua{sv}");
  std::uint32_t node = 0;
  std::ifstream(config.node_file) >> node;
  sd_bus_message_append(reply, "u", node);
  sd_bus_message_open_container(reply, 'a', "{sv}");
  sd_bus_message_append(reply, "{sv}", "source_type", "u", 1u);
  sd_bus_message_append(reply, "{sv}", "size", "(ii)", config.width, config.height);
  sd_bus_message_close_container(reply);
  sd_bus_message_close_container(reply);
  sd_bus_message_close_container(reply);
  sd_bus_message_close_container(reply);
  sd_bus_message_close_container(reply);
  if (config.persist_mode != 0) {
    sd_bus_message_append(reply, "{sv}", "persist_mode", "u", config.persist_mode);
    sd_bus_message_append(reply, "{sv}", "restore_data", "(suv)", "nelf-test", 1u, "s", "monitor");
  }
  if ((r = sd_bus_message_close_container(reply)) < 0) return r;
  log_event("started");
  return sd_bus_send(nullptr, reply, nullptr);
}

int property(sd_bus*, const char*, const char*, const char* name, sd_bus_message* reply, void*, sd_bus_error*) {
  const std::uint32_t value = std::strcmp(name, "AvailableSourceTypes") == 0   ? 1u | 2u
                              : std::strcmp(name, "AvailableCursorModes") == 0 ? 1u | 2u
                                                                               : 4u;
  return sd_bus_message_append(reply, "u", value);
}

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const sd_bus_vtable kScreenCastVtable[] = {
    SD_BUS_VTABLE_START(0),
    SD_BUS_METHOD("CreateSession", "oosa{sv}", "ua{sv}", create_session, SD_BUS_VTABLE_UNPRIVILEGED),
    SD_BUS_METHOD("SelectSources", "oosa{sv}", "ua{sv}", select_sources, SD_BUS_VTABLE_UNPRIVILEGED),
    SD_BUS_METHOD("Start", "oossa{sv}", "ua{sv}", start, SD_BUS_VTABLE_UNPRIVILEGED),
    SD_BUS_PROPERTY("AvailableSourceTypes", "u", property, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY("AvailableCursorModes", "u", property, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_PROPERTY("version", "u", property, 0, SD_BUS_VTABLE_PROPERTY_CONST),
    SD_BUS_VTABLE_END};
#pragma GCC diagnostic pop

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--node-file")
      config.node_file = value;
    else if (key == "--width")
      config.width = std::atoi(value.c_str());
    else if (key == "--height")
      config.height = std::atoi(value.c_str());
    else if (key == "--answer")
      config.answer = value;
    else if (key == "--log")
      config.log = value;
  }
  if (config.log.empty() || config.node_file.empty()) {
    std::fprintf(stderr, "usage: %s --node-file FILE --width W --height H --answer accept|cancel|never --log FILE\n",
                 argv[0]);
    return 2;
  }
  signal(SIGTERM, [](int) { stopping = 1; });
  signal(SIGINT, [](int) { stopping = 1; });
  sd_bus* raw = nullptr;
  if (sd_bus_open_user(&raw) < 0) return 1;
  const std::unique_ptr<sd_bus, BusDeleter> bus(raw);
  sd_bus_slot* raw_slot = nullptr;
  if (sd_bus_add_object_vtable(bus.get(), &raw_slot, "/org/freedesktop/portal/desktop",
                               "org.freedesktop.impl.portal.ScreenCast", kScreenCastVtable, nullptr) < 0)
    return 1;
  const std::unique_ptr<sd_bus_slot, SlotDeleter> slot(raw_slot);
  if (sd_bus_request_name(bus.get(), "org.freedesktop.impl.portal.desktop.nelftest", 0) < 0) return 1;
  std::ofstream(config.log + ".ready") << "on the bus\n";  // the test waits for this
  while (!stopping) {
    const int r = sd_bus_process(bus.get(), nullptr);
    if (r < 0) return 1;
    if (r == 0) sd_bus_wait(bus.get(), 200'000);
  }
  pending_dialog.reset();
  session_slot.reset();
  return 0;
}
