#include "hmz_output/modeline.hpp"

#include <fmt/format.h>

#include <cmath>

namespace nelf {

std::string xrandr_mode_name(const VideoTiming& timing) {
  return fmt::format("{}x{}_{}_fp", timing.h_active, timing.v_active, std::lround(timing.refresh_hz()));
}

std::string xrandr_newmode_arguments(const VideoTiming& t) {
  return fmt::format("\"{}\" {:.2f} {} {} {} {} {} {} {} {} {}hsync {}vsync", xrandr_mode_name(t), t.pixel_clock_mhz,
                     t.h_active, t.h_sync_start, t.h_sync_end, t.h_total, t.v_active, t.v_sync_start, t.v_sync_end,
                     t.v_total, t.h_sync_positive ? '+' : '-', t.v_sync_positive ? '+' : '-');
}

std::vector<std::string> xrandr_commands(const VideoTiming& timing, const std::string& output) {
  const std::string name = xrandr_mode_name(timing);
  return {
      "xrandr --newmode " + xrandr_newmode_arguments(timing),
      fmt::format("xrandr --addmode {} {}", output, name),
      fmt::format("xrandr --output {} --mode {}", output, name),
  };
}

}  // namespace nelf
