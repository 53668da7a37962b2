#include "hmz_output/kms_modes.hpp"

#include <fmt/format.h>
#include <xf86drmMode.h>

#include <algorithm>
#include <cmath>

namespace nelf {
namespace {

// The refresh of a signal: its packed timing runs at twice the 2D clock over twice the lines, so
// it is also the refresh of the 2D timing the kernel reports for the 3D mode.
double signal_refresh(const Signal& signal) { return signal.timing ? signal.timing->refresh_hz() : 0.0; }

std::string format_hz(double hz) {
  const double whole = std::round(hz);
  if (std::abs(hz - whole) < 0.005) return fmt::format("{}", static_cast<int>(whole));
  return fmt::format("{:.2f}", hz);
}

bool fits_size(const KmsMode& mode, const Signal& signal) {
  return mode.hdisplay == signal.eye_width && mode.vdisplay == signal.eye_height &&
         mode.vtotal - mode.vdisplay == signal.gap_rows;
}

bool fits(const KmsMode& mode, const Signal& signal) {
  return mode.is_frame_packing() && !mode.is_interlaced() && fits_size(mode, signal) &&
         same_refresh(mode.refresh_hz(), signal_refresh(signal));
}

bool preferred(const KmsMode& mode) { return (mode.type & DRM_MODE_TYPE_PREFERRED) != 0; }

// The best fitting mode of a connector, if any: closest refresh, then preferred, then first.
std::optional<std::size_t> best_mode(const KmsConnector& connector, const Signal& signal) {
  std::optional<std::size_t> best;
  const double want = signal_refresh(signal);
  for (std::size_t i = 0; i < connector.modes.size(); ++i) {
    const KmsMode& m = connector.modes[i];
    if (!fits(m, signal)) continue;
    if (!best) {
      best = i;
      continue;
    }
    const KmsMode& b = connector.modes[*best];
    const double dm = std::abs(m.refresh_hz() - want);
    const double db = std::abs(b.refresh_hz() - want);
    if (dm < db - 1e-9 || (std::abs(dm - db) <= 1e-9 && preferred(m) && !preferred(b))) best = i;
  }
  return best;
}

bool has_frame_packing(const KmsConnector& connector) {
  return std::any_of(connector.modes.begin(), connector.modes.end(),
                     [](const KmsMode& m) { return m.is_frame_packing(); });
}

// "1920x1080@24 FP (hdmi-fp-1080p24), 1280x720@50 FP", each description once.
std::string list_frame_packing_modes(const KmsConnector& connector) {
  std::vector<std::string> seen;
  std::string out;
  for (const KmsMode& m : connector.modes) {
    if (!m.is_frame_packing()) continue;
    std::string text = m.describe();
    if (const auto s = signal_for_mode(m)) text += " (" + *s + ")";
    if (std::find(seen.begin(), seen.end(), text) != seen.end()) continue;
    out += (out.empty() ? "" : ", ") + text;
    seen.push_back(std::move(text));
  }
  return out;
}

// The nelf signals the connector's frame-packing modes carry, each once, in list order.
std::vector<std::string> offered_signals(const KmsConnector& connector) {
  std::vector<std::string> names;
  for (const KmsMode& m : connector.modes)
    if (const auto s = signal_for_mode(m); s && std::find(names.begin(), names.end(), *s) == names.end())
      names.push_back(*s);
  return names;
}

std::string list_connectors(const KmsDevice& device) {
  std::string out;
  for (const KmsConnector& c : device.connectors)
    out += fmt::format("{}{} ({})", out.empty() ? "" : ", ", c.name, c.connected ? "connected" : "disconnected");
  return out;
}

std::string device_label(const KmsDevice& device) {
  if (device.driver.empty()) return device.path;
  return fmt::format("{} ({})", device.path, device.driver);
}

// Why a connector shows no 3D modes, naming the drivers known to expose them or not.
std::string no_stereo_reason(const KmsDevice& device) {
  const std::string& d = device.driver;
  if (d == "nvidia-drm" || d == "nvidia" || d == "amdgpu" || d == "radeon")
    return fmt::format(
        "driver {} exposes no HDMI stereo modes (i915, nouveau and vc4 do; nvidia-drm and mainline amdgpu do not): "
        "connect the HMD to an Intel, nouveau or Raspberry Pi output, or use --output quad-buffer or --output "
        "fullscreen",
        d);
  return fmt::format(
      "the monitor advertises no HDMI 3D modes in its EDID, or driver {} does not expose stereo modes (i915, nouveau "
      "and vc4 do; nvidia-drm and mainline amdgpu do not); check that the HMD is switched on and connected directly",
      d.empty() ? "of this device" : d);
}

std::string wanted_mode(const Signal& signal) {
  return fmt::format("{}x{}@{} FP ({})", signal.eye_width, signal.eye_height, format_hz(signal_refresh(signal)),
                     signal.name);
}

std::string suggest_signals(const std::vector<std::string>& names) {
  if (names.empty())
    return "none of them is a frame-packed signal nelf sends (hdmi-fp-720p60, hdmi-fp-720p50, "
           "hdmi-fp-1080p24)";
  std::string list;
  for (std::size_t i = 0; i < names.size(); ++i)
    list += (i == 0 ? "" : (i + 1 == names.size() ? " or " : ", ")) + ("\"" + names[i] + "\"");
  return fmt::format("use a profile whose [output] signal is {} (--profile FILE)", list);
}

}  // namespace

double KmsMode::refresh_hz() const {
  if (clock_khz > 0 && htotal > 0 && vtotal > 0) {
    double hz = clock_khz * 1000.0 / (static_cast<double>(htotal) * vtotal);
    if (is_interlaced()) hz *= 2;  // fields per second, as the kernel's vrefresh counts them
    return hz;
  }
  return vrefresh;
}

bool KmsMode::is_frame_packing() const { return (flags & DRM_MODE_FLAG_3D_MASK) == DRM_MODE_FLAG_3D_FRAME_PACKING; }

bool KmsMode::is_interlaced() const { return (flags & DRM_MODE_FLAG_INTERLACE) != 0; }

std::string KmsMode::describe() const {
  return fmt::format("{}x{}{}@{}{}", hdisplay, vdisplay, is_interlaced() ? "i" : "", format_hz(refresh_hz()),
                     is_frame_packing() ? " FP" : "");
}

bool same_refresh(double a, double b) {
  if (a <= 0 || b <= 0) return false;
  return std::abs(a - b) <= kRefreshTolerance * std::max(a, b);
}

std::optional<std::string> signal_for_mode(const KmsMode& mode) {
  if (!mode.is_frame_packing() || mode.is_interlaced()) return std::nullopt;
  for (const auto name : signal_names()) {
    const auto s = find_signal(name);
    if (s && s->kind == SignalKind::hdmi_frame_packing && fits(mode, *s)) return std::string(name);
  }
  return std::nullopt;
}

std::string kms_connector_name(std::uint32_t type, std::uint32_t type_id) {
  const char* name = drmModeGetConnectorTypeName(type);
  if (!name) return fmt::format("Unknown{}-{}", type, type_id);
  return fmt::format("{}-{}", name, type_id);
}

KmsModeSelection select_kms_mode(const KmsDevice& device, const std::string& wanted_connector, const Signal& signal) {
  KmsModeSelection result;
  const auto fail = [&](std::string why) {
    result.error = std::move(why);
    return result;
  };
  if (signal.kind != SignalKind::hdmi_frame_packing || !signal.timing)
    return fail(
        fmt::format("--output kms sends HDMI 1.4a frame packing, but signal '{}' is not frame-packed; use a "
                    "profile whose [output] signal is hdmi-fp-720p60, hdmi-fp-720p50 or hdmi-fp-1080p24",
                    signal.name));
  if (device.connectors.empty())
    return fail(
        fmt::format("{} has no display connectors (a render-only GPU?); use --output window", device_label(device)));

  const auto choose = [&](std::size_t ci, std::size_t mi) {
    const KmsConnector& c = device.connectors[ci];
    const KmsMode& m = c.modes[mi];
    result.choice = KmsModeChoice{ci, mi, c.name, m.packed_width(), m.packed_height(), m.refresh_hz()};
    return result;
  };
  const auto wrong_modes = [&](const KmsConnector& c) {
    return fmt::format("{} offers 3D frame packing only as {}, not the signal's {}: {}", c.name,
                       list_frame_packing_modes(c), wanted_mode(signal), suggest_signals(offered_signals(c)));
  };

  if (!wanted_connector.empty()) {
    const auto it = std::find_if(device.connectors.begin(), device.connectors.end(),
                                 [&](const KmsConnector& c) { return c.name == wanted_connector; });
    if (it == device.connectors.end())
      return fail(fmt::format("connector '{}' not found on {}; it has {}", wanted_connector, device_label(device),
                              list_connectors(device)));
    const KmsConnector& c = *it;
    if (!c.connected)
      return fail(fmt::format("connector {} on {} is not connected: plug the HMD in and switch it on (connectors: {})",
                              c.name, device_label(device), list_connectors(device)));
    if (const auto m = best_mode(c, signal))
      return choose(static_cast<std::size_t>(it - device.connectors.begin()), *m);
    if (!has_frame_packing(c))
      return fail(fmt::format("{} offers no 3D frame-packing modes ({} 2D modes): {}", c.name, c.modes.size(),
                              no_stereo_reason(device)));
    return fail(wrong_modes(c));
  }

  std::vector<const KmsConnector*> connected;
  for (std::size_t i = 0; i < device.connectors.size(); ++i) {
    const KmsConnector& c = device.connectors[i];
    if (!c.connected) continue;
    connected.push_back(&c);
    if (const auto m = best_mode(c, signal)) return choose(i, *m);
  }
  if (connected.empty())
    return fail(fmt::format("no display connected to {} (connectors: {}): plug the HMD in and switch it on",
                            device_label(device), list_connectors(device)));

  std::vector<const KmsConnector*> stereo;
  for (const KmsConnector* c : connected)
    if (has_frame_packing(*c)) stereo.push_back(c);
  if (stereo.empty()) {
    std::string counts;
    for (const KmsConnector* c : connected)
      counts += fmt::format("{}{}: {} 2D modes", counts.empty() ? "" : ", ", c->name, c->modes.size());
    return fail(
        fmt::format("no connected display offers a 3D frame-packing mode ({}): {}", counts, no_stereo_reason(device)));
  }
  if (stereo.size() == 1) return fail(wrong_modes(*stereo.front()));
  std::string all;
  for (const KmsConnector* c : stereo) all += (all.empty() ? "" : "; ") + wrong_modes(*c);
  return fail(all);
}

}  // namespace nelf
