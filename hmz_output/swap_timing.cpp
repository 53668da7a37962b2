#include "hmz_output/swap_timing.hpp"

#include <algorithm>

namespace nelf {

bool swaps_wait_for_vblank(std::vector<double> intervals, double refresh_hz) {
  if (intervals.empty() || refresh_hz <= 0) return false;
  std::sort(intervals.begin(), intervals.end());
  const double period = 1.0 / refresh_hz;
  const double median = intervals[intervals.size() / 2];
  return median > 0.75 * period && median < 1.5 * period && intervals.front() > 0.5 * period;
}

}  // namespace nelf
