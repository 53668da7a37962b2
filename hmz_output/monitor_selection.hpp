#pragma once
// Which monitor `--output fullscreen` uses (DESIGN.md §7): pure logic over the monitors the window
// system reports, so that it is unit-tested without an X server.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "hmz_output/signal.hpp"

namespace nelf {

struct MonitorInfo {
  std::string name;   // the window system's name (X11/RandR: the output, e.g. "HDMI-1")
  std::string model;  // the monitor's own name from its EDID, e.g. "HMZ-T1" ("" when unknown)
  int width = 0;      // current mode
  int height = 0;
  double refresh_hz = 0.0;  // 0 = unknown
};

struct MonitorChoice {
  std::optional<std::size_t> index;  // the chosen monitor, or nullopt with `error` set
  std::string error;                 // what went wrong and what to do (may span lines: xrandr commands)
};

// The monitor named `wanted` (case-insensitive; its output name or EDID model, whole name first, else
// a unique partial match; "" = one containing "HMZ") whose current mode is `packed`. Errors: no
// monitors, none matches (lists every monitor with its mode, says to pass --monitor NAME), several
// match, or the match is not in the packed mode (with the xrandr commands for `signal`'s timing).
MonitorChoice choose_monitor(const std::vector<MonitorInfo>& monitors, const std::string& wanted,
                             std::array<int, 2> packed, const Signal& signal);

// The monitor name (display descriptor 0xFC) of an EDID base block, "" when it has none or the
// block is too short. The HMZ-T1's is "HMZ-T1"; X11 names monitors by output ("HDMI-1"), so this is
// what makes the default "HMZ" match.
std::string edid_monitor_name(const std::vector<unsigned char>& edid);

// "HDMI-1 (HMZ-T1) 1280x1470 at 60 Hz"
std::string describe_monitor(const MonitorInfo& monitor);

}  // namespace nelf
