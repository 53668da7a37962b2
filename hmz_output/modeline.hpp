#pragma once
// xrandr mode lines for the frame-packed signals (DESIGN.md §7), so that a user whose monitor (the
// HMD) is not in the packed mode can add it: `xrandr --newmode`, `--addmode`, `--output … --mode`.
#include <string>
#include <vector>

#include "hmz_output/signal.hpp"

namespace nelf {

// "1280x1470_60_fp": active size, refresh rounded to whole hertz, "_fp" for frame packing.
std::string xrandr_mode_name(const VideoTiming& timing);
// The arguments of `xrandr --newmode`: "\"1280x1470_60_fp\" 148.50 1280 1390 1430 1650 1470 1475
// 1480 1500 +hsync +vsync" (clock in MHz, then the horizontal and vertical timings).
std::string xrandr_newmode_arguments(const VideoTiming& timing);
// The three commands that add the mode to `output` and switch it on.
std::vector<std::string> xrandr_commands(const VideoTiming& timing, const std::string& output);

}  // namespace nelf
