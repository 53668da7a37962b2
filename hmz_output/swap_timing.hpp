#pragma once
// Whether buffer swaps wait for the vertical blank, judged from how long they took: a window
// display reports vsync() only when they do, so that the player paces frames itself otherwise.
#include <vector>

namespace nelf {

// True when timed swap intervals (seconds, with swap interval 1 and nothing else to do between them)
// look like a display refreshing at `refresh_hz`: the median within [0.75, 1.5] periods and none
// shorter than half a period. Swaps that return at once (no vblank: Xvfb, software GL, a driver that
// ignores the interval) or that are merely slow and irregular do not count. False when empty.
bool swaps_wait_for_vblank(std::vector<double> intervals, double refresh_hz);

}  // namespace nelf
