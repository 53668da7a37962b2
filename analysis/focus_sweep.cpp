#include "analysis/focus_sweep.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace nelf {

std::vector<double> accommodation_steps(double max_diopters, double step_diopters) {
  if (!(step_diopters > 0.0) || !(max_diopters >= 0.0))
    throw std::invalid_argument("accommodation steps need a positive step and a non-negative range");
  std::vector<double> steps;
  // Counted rather than accumulated, so 4.5 D in 0.25 D steps ends at 4.5 exactly.
  const int count = static_cast<int>(std::floor(max_diopters / step_diopters + 1e-9));
  for (int k = 0; k <= count; ++k) steps.push_back(k * step_diopters);
  return steps;
}

double peak_position(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.empty() || x.size() != y.size()) throw std::invalid_argument("peak_position: empty or mismatched samples");
  // Non-finite PSNR (identical images) is the best there is.
  const auto value = [&](std::size_t k) {
    return std::isfinite(y[k]) ? y[k] : (y[k] > 0 ? std::numeric_limits<double>::max() : -1e300);
  };
  std::size_t best = 0;
  for (std::size_t k = 1; k < y.size(); ++k)
    if (value(k) > value(best)) best = k;
  if (best == 0 || best + 1 == y.size() || !std::isfinite(y[best - 1]) || !std::isfinite(y[best]) ||
      !std::isfinite(y[best + 1]))
    return x[best];
  // Vertex of the parabola through the three samples (uniform or not).
  const double x0 = x[best - 1], x1 = x[best], x2 = x[best + 1];
  const double y0 = y[best - 1], y1 = y[best], y2 = y[best + 1];
  const double d0 = (y1 - y0) / (x1 - x0), d1 = (y2 - y1) / (x2 - x1);
  const double curvature = (d1 - d0) / (x2 - x0);
  if (!(curvature < 0.0)) return x1;
  const double vertex = 0.5 * (x0 + x1) - d0 / (2.0 * curvature);
  return std::clamp(vertex, x0, x2);
}

FocusSweep sweep_focus(const EyeSimulator& simulator, const Image& displayed, const EyeModel& eye,
                       const SceneDepth* scene, const std::vector<RetinalRegion>& regions,
                       const std::vector<double>& accommodation_diopters) {
  if (accommodation_diopters.empty()) throw std::invalid_argument("focus sweep: no accommodations");
  EyeModel pinhole = eye;
  pinhole.pupil_samples_per_axis = 1;  // one ray through the pupil's centre: everything in focus
  const Image sharp = simulator.ideal(pinhole, scene);
  const auto clear = simulator.clear_field_mask(eye.pupil_mm);

  FocusSweep sweep;
  sweep.accommodation_diopters = accommodation_diopters;
  std::vector<std::vector<std::uint8_t>> masks;
  for (const RetinalRegion& region : regions) {
    if (region.mask.size() != clear.size())
      throw std::invalid_argument(fmt::format("focus sweep: region '{}' has a mask of another size", region.name));
    std::vector<std::uint8_t> mask(clear.size());
    std::size_t count = 0;
    for (std::size_t k = 0; k < mask.size(); ++k) count += mask[k] = region.mask[k] && clear[k] ? 1 : 0;
    if (count == 0)
      throw std::invalid_argument(fmt::format("focus sweep: region '{}' is outside the clear field", region.name));
    masks.push_back(std::move(mask));
    sweep.regions.push_back({region.name, region.depth_mm, {}, 0.0});
  }
  EyeModel focused = eye;
  for (double diopters : accommodation_diopters) {
    focused.focus_mm = diopters > 0.0 ? 1000.0 / diopters : std::numeric_limits<double>::infinity();
    const Image retina = simulator.retina(displayed, focused);
    for (std::size_t r = 0; r < regions.size(); ++r)
      sweep.regions[r].psnr_db.push_back(psnr_db(retina, sharp, masks[r]));
  }
  for (FocusCurve& curve : sweep.regions)
    curve.best_focus_diopters = peak_position(accommodation_diopters, curve.psnr_db);
  return sweep;
}

}  // namespace nelf
