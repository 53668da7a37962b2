#pragma once
// The desktop's ScreenCast portal (org.freedesktop.portal.ScreenCast, xdg-desktop-portal with the
// desktop's backend: GNOME, KDE, wlroots), for `pipewire:` without a node: the user chooses a screen
// or a window in the desktop's own dialog and the portal hands nelf a PipeWire connection that sees
// only that stream. The portal's restore token is kept in $XDG_STATE_HOME/nelf (default
// ~/.local/state/nelf), so the user is asked once and later runs take the same choice back.
#include <atomic>
#include <memory>
#include <optional>
#include <string>

#include "core/unix_socket.hpp"

namespace nelf {

struct ScreenCastPortalOptions {
  bool restore = true;  // offer the kept restore token (false: ask the user again)
};

// One screen cast, open while the object lives (its portal session is closed with it).
class ScreenCastPortal {
 public:
  // Asks the portal on the session bus ($DBUS_SESSION_BUS_ADDRESS) for a screen cast of one monitor
  // or window, without the cursor where the portal allows, and waits for the user's choice (for as
  // long as the dialog is open). Throws UserError, status 1, with one line for: no session bus, no
  // ScreenCast portal on it, the user cancelling, the portal failing; `stop` (may be null) ends the
  // wait with status 130. `input` prefixes the messages.
  ScreenCastPortal(const ScreenCastPortalOptions& options, const std::string& input,
                   const std::atomic<bool>* stop = nullptr);
  ~ScreenCastPortal();
  ScreenCastPortal(const ScreenCastPortal&) = delete;
  ScreenCastPortal& operator=(const ScreenCastPortal&) = delete;

  // The PipeWire node of the stream the user chose.
  unsigned node_id() const;
  // "monitor" or "window", as the portal says; empty when it does not.
  const std::string& source_type() const;
  // The connection to PipeWire the portal opened for this cast (once; afterwards an empty fd).
  UniqueFd take_pipewire_fd();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace nelf
