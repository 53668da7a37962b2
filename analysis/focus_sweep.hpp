#pragma once
// Where an eye focuses best on each region of a scene (issue #15): the retina through the display
// at a series of accommodations, each region's PSNR against the all-in-focus view of the scene (a
// pinhole pupil: no defocus), and the accommodation where each region is sharpest. On the flat
// emulated screen every region is sharpest at the screen's distance; a display whose focus follows
// the content puts each region's best focus at its own depth.
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/eye_simulator.hpp"

namespace nelf {

// A region of the scene as the retina sees it: `mask` per retinal pixel (the simulator's field).
struct RetinalRegion {
  std::string name;
  double depth_mm = 0;
  std::vector<std::uint8_t> mask;
};

struct FocusCurve {
  std::string name;
  double depth_mm = 0;
  std::vector<double> psnr_db;     // per accommodation, against the all-in-focus scene
  double best_focus_diopters = 0;  // the peak, refined between samples (a parabola through three)
};

struct FocusSweep {
  std::vector<double> accommodation_diopters;  // 0 = infinity
  std::vector<FocusCurve> regions;
};

// The accommodations 0, step, 2 step, … up to `max_diopters`.
std::vector<double> accommodation_steps(double max_diopters, double step_diopters);

// The sweep of `eye` (its focus is replaced by each accommodation) looking through the display at
// `displayed`, judged against the all-in-focus scene (`scene`: the real scene; null: the flat
// screen). Each region's mask is combined with the clear field of the eye's pupil. Throws
// std::invalid_argument for no accommodations or a region the clear field leaves empty.
FocusSweep sweep_focus(const EyeSimulator& simulator, const Image& displayed, const EyeModel& eye,
                       const SceneDepth* scene, const std::vector<RetinalRegion>& regions,
                       const std::vector<double>& accommodation_diopters);

// The x of the largest y, refined by the parabola through it and its neighbours (the sample itself
// at either end). Throws std::invalid_argument for empty or mismatched input.
double peak_position(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace nelf
