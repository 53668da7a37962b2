#include "analysis/comfort_zone.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nelf {

namespace {
// Shibata et al. 2011, the lines fitted to their experiments 1 and 2 (slope, intercept in diopters).
constexpr double far_slope = 1.035, far_intercept = -0.626;
constexpr double near_slope = 1.129, near_intercept = 0.442;
}  // namespace

AccommodationRange comfortable_accommodation(double vergence_diopters) {
  if (!std::isfinite(vergence_diopters) || vergence_diopters < 0.0)
    throw std::invalid_argument("comfortable_accommodation: the vergence must be a finite distance in diopters");
  // Focus farther than the near boundary allows leaves the eyes converged too near for it; nearer
  // than the far boundary allows, converged too far.
  AccommodationRange range;
  range.farthest_diopters = std::max(0.0, (vergence_diopters - near_intercept) / near_slope);
  range.nearest_diopters = (vergence_diopters - far_intercept) / far_slope;
  return range;
}

}  // namespace nelf
