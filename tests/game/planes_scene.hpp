#pragma once
// The test game's `--scene planes` (nelf_test_game.cpp): two textured planes drawn in perspective
// with a depth buffer, as a 3D game draws, by a pair of parallel cameras with off-axis frusta that
// meet at kConvergence. The tests of the game's depth (inputs/game_depth.hpp) compare what nelf makes
// of the depth buffers with the disparity this geometry gives, here.
#include <cmath>

namespace nelf::test_game {

inline constexpr double kFovX_deg = 60;         // the horizontal field of view
inline constexpr double kEyeSeparation = 0.06;  // scene units (metres)
inline constexpr double kConvergence = 1.0;     // where the eyes' pictures coincide: disparity 0
inline constexpr double kNearClip = 0.1, kFarClip = 10.0;
inline constexpr double kNearPlane = 0.5;  // in front of the convergence distance
inline constexpr double kFarPlane = 2.0;   // behind it, filling the view
// The near plane's extent, in scene units around the view axis: left, right, bottom, top.
inline constexpr double kNearLeft = -0.2, kNearRight = 0.05, kNearBottom = -0.1, kNearTop = 0.1;

// The disparity (left-view pixel x shows the point the right view shows at x − d) of a point at
// distance z, for views `width` pixels wide: f·e·(1/z − 1/c), f the focal length in pixels.
inline double half_fov_tangent() { return std::tan(kFovX_deg / 2 * 3.14159265358979323846 / 180); }
inline double planes_disparity(int width, double z) {
  const double focal_px = 0.5 * width / half_fov_tangent();
  return focal_px * kEyeSeparation * (1.0 / z - 1.0 / kConvergence);
}

}  // namespace nelf::test_game
