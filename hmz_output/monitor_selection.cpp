#include "hmz_output/monitor_selection.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>

#include "hmz_output/modeline.hpp"

namespace nelf {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool contains(const std::string& haystack, const std::string& needle) {
  return !haystack.empty() && lower(haystack).find(lower(needle)) != std::string::npos;
}

bool equals(const std::string& a, const std::string& b) { return !a.empty() && lower(a) == lower(b); }

std::string list_monitors(const std::vector<MonitorInfo>& monitors) {
  std::string list;
  for (const auto& m : monitors) list += (list.empty() ? "" : ", ") + describe_monitor(m);
  return list;
}

}  // namespace

std::string edid_monitor_name(const std::vector<unsigned char>& edid) {
  if (edid.size() < 128) return {};
  // Four 18-byte descriptors at 54, 72, 90 and 108; a display descriptor starts 00 00 00 TAG 00.
  for (std::size_t offset = 54; offset <= 108; offset += 18) {
    const unsigned char* d = edid.data() + offset;
    if (d[0] != 0 || d[1] != 0 || d[2] != 0 || d[3] != 0xFC) continue;
    std::string name;
    for (int i = 5; i < 18 && d[i] != 0x0A; ++i)
      if (d[i] >= 0x20 && d[i] < 0x7F) name += static_cast<char>(d[i]);
    while (!name.empty() && name.back() == ' ') name.pop_back();
    return name;
  }
  return {};
}

std::string describe_monitor(const MonitorInfo& m) {
  std::string text = m.name;
  if (!m.model.empty() && m.model != m.name) text += " (" + m.model + ")";
  text += fmt::format(" {}x{}", m.width, m.height);
  if (m.refresh_hz > 0) text += fmt::format(" at {:g} Hz", std::round(m.refresh_hz * 100) / 100);
  return text;
}

MonitorChoice choose_monitor(const std::vector<MonitorInfo>& monitors, const std::string& wanted,
                             std::array<int, 2> packed, const Signal& signal) {
  if (monitors.empty()) return {std::nullopt, "fullscreen: the window system reports no monitors"};
  const std::string pattern = wanted.empty() ? "HMZ" : wanted;
  const std::string how = wanted.empty() ? fmt::format("no monitor name contains \"{}\"", pattern)
                                         : fmt::format("no monitor is named \"{}\"", pattern);

  std::vector<std::size_t> matches;
  for (std::size_t i = 0; i < monitors.size(); ++i)
    if (equals(monitors[i].name, pattern) || equals(monitors[i].model, pattern)) matches.push_back(i);
  if (matches.empty())
    for (std::size_t i = 0; i < monitors.size(); ++i)
      if (contains(monitors[i].name, pattern) || contains(monitors[i].model, pattern)) matches.push_back(i);

  if (matches.empty())
    return {std::nullopt,
            fmt::format("fullscreen: {}; connected monitors: {}; pass --monitor NAME", how, list_monitors(monitors))};
  if (matches.size() > 1) {
    std::vector<MonitorInfo> matching;
    for (auto i : matches) matching.push_back(monitors[i]);
    return {std::nullopt, fmt::format("fullscreen: several monitors match \"{}\": {}; pass --monitor with a full name",
                                      pattern, list_monitors(matching))};
  }

  const MonitorInfo& chosen = monitors[matches.front()];
  if (chosen.width == packed[0] && chosen.height == packed[1]) return {matches.front(), {}};

  // 1:1 pixels are the point of fullscreen on an HMD (each elemental image must land on the panel's
  // pixels behind its lenslet), so a scaled picture is refused rather than shown.
  std::string error = fmt::format("fullscreen: monitor {} is in mode {}x{}, but the {} signal needs {}x{} pixels 1:1",
                                  chosen.name, chosen.width, chosen.height, signal.name, packed[0], packed[1]);
  if (signal.timing && signal.timing->h_active == packed[0] && signal.timing->v_active == packed[1]) {
    error += "; add and select the mode with:";
    for (const auto& command : xrandr_commands(*signal.timing, chosen.name)) error += "\n  " + command;
  } else {
    error +=
        fmt::format("; switch the monitor to a {}x{} mode (xrandr --output {} --mode {}x{}) or use --output window",
                    packed[0], packed[1], chosen.name, packed[0], packed[1]);
  }
  return {std::nullopt, error};
}

}  // namespace nelf
