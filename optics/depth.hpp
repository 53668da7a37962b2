#pragma once
// The content's depth, as the compositor and the eye simulator use it: the disparity of a view
// (core/view_disparity.hpp) turned into distance with the emulated screen's geometry, and the
// search along a ray for where it meets the content's surface. Pure math, shared by the CPU paths
// and mirrored by shaders/elemental.frag (NELF_DEPTH).
//
// Geometry. Both eyes look at the emulated screen at distance D (render distance d_r) from their
// pupils, their centres an IPD e apart. A scene point at distance Z seen by the left eye at screen
// position x_L and by the right eye at x_R has the screen disparity δ = x_L − x_R = e (D/Z − 1) (mm
// on the screen): 0 on the screen, > 0 in front of it, → −e at infinity. So 1/Z = (1 + δ/e)/D.
//
// A ray that crosses the pupil plane at p (mm, this eye's coordinates) and meets the flat screen at
// v shows, in a view taken from the pupil's centre, the scene point at the screen position
// v + p δ/e, where δ is the disparity of the surface there: the view seen from a pupil point p is
// the view from the centre shifted by p/e of its disparity (p = ±e is the other eye's view). The
// front-most δ with δ = disparity(v + p δ/e) is where the ray meets the surface.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "core/view_disparity.hpp"
#include "optics/mapping.hpp"

namespace nelf {

// The screen geometry the conversion needs: D, the screen's size (mm) and e.
struct DepthGeometry {
  double screen_distance_mm = 0;
  Vec2 screen_size_mm;
  double ipd_mm = 0;
};

// The geometry of `mapping` (a lens-array eye) under `profile`'s IPD.
DepthGeometry depth_geometry(const Profile& profile, const EyeMapping& mapping);

// δ (mm on the screen) of a point at distance `depth_mm` from the pupil; and back (+inf for δ ≤ −e:
// at or beyond infinity).
double disparity_mm_from_depth(const DepthGeometry& g, double depth_mm);
double depth_mm_from_disparity(const DepthGeometry& g, double disparity_mm);

// A view's disparity as a surface the compositor searches: per map texel the disparity in units of
// the screen's width (δ / W; what the shader's texture holds), unknown texels (NaN: occluded in the
// other view, or unmatched) filled with the farther of the known texels either side of them in
// their row (a row with none: the screen, 0), and the range of the values.
class DisparitySurface {
 public:
  // Throws std::invalid_argument for a map whose size does not match its values or is empty.
  explicit DisparitySurface(const ViewDisparity& disparity);

  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<float>& values() const { return values_; }  // row-major, δ / W
  float front() const { return front_; }                        // the largest value (nearest)
  float back() const { return back_; }                          // the smallest value (farthest)
  // True when every texel was unknown (the surface is then the flat screen).
  bool unknown() const { return unknown_; }

  // The value at screen coordinate uv (u right, t down, in [0, 1]; clamped to the map), nearest texel.
  float at(Vec2 uv) const;

  // Per tile of depth_bound_tile × depth_bound_tile texels (row-major, bound_width() × bound_height()),
  // the largest value of the tile and its eight neighbours: no texel within depth_bound_tile − 1
  // texels of one in the tile (per axis) is nearer.
  const std::vector<float>& front_bounds() const { return bounds_; }
  int bound_width() const { return bound_width_; }
  int bound_height() const { return bound_height_; }

  // Where on the screen (uv) a ray shows the surface: the ray meets the flat screen at `flat_uv` and
  // shifts by `gain` (uv) per unit of δ / W (pupil_gain of its pupil-plane crossing). The front-most
  // crossing, exact for the nearest-texel surface: the ray walks the texels it crosses from the front
  // of the range to its back; in a texel of value v that it enters at δ / W = a and leaves at b < a
  // it is at or behind the surface from v down, so it crosses at min(v, a) when v ≥ b. The walk
  // starts where the ray falls to the front bound of the tile it starts in, or leaves the texels that
  // bound holds for, whichever comes first: nothing before is near enough to cross it. A surface of
  // one value v gives flat_uv + gain · v exactly (0: flat_uv).
  Vec2 hit(Vec2 flat_uv, Vec2 gain) const;
  // The same search in the shader's float arithmetic, step for step (shaders/depth_search.glsl's
  // surface_hit), for the CPU depth-aware composite (compositor/cpu/composite_table.hpp): the δ / W
  // where the ray (flat point (u, v), gain (gain_u, gain_v)) meets the surface. Inline: it is that
  // path's inner loop. One difference: a ray that does not move (no gain: the display's black
  // pixels, whose crossing no part of the picture takes) gives the texel it starts in at once,
  // where the shader walks all depth_search_texels steps in place; on the CPU those steps were most
  // of the search's time, on llvmpipe the early return cost more than it saved.
  float crossing(float u, float v, float gain_u, float gain_v) const;
  // crossing() of `count` rays, each four floats in `rays` (u, v, gain_u, gain_v), into `out`: eight
  // at a time with AVX2 where the CPU has it (the same operations in the same order, so the same
  // values), one at a time elsewhere.
  void crossings(const float* rays, int count, float* out) const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<float> values_;
  int bound_width_ = 0, bound_height_ = 0;
  std::vector<float> bounds_;
  float front_ = 0.f, back_ = 0.f;
  bool unknown_ = false;
};

// The most texels a ray's search visits (the shader's too): a ray moves by its pupil-plane crossing
// over e times the frame's disparity range, a few texels of the map; past this many it is taken to
// show the back of the range.
inline constexpr int depth_search_texels = 48;
// The side of a tile of the surface's front bounds, in texels (the shader's too): with a tile's
// bound a ray in front of a far region skips to it and crosses a texel or two, rather than walking
// down from the front of the whole frame's range (docs/PERFORMANCE.md).
inline constexpr int depth_bound_tile = 8;

inline float DisparitySurface::crossing(float u, float v, float gain_u, float gain_v) const {
  // GLSL's min and max (the second operand when the comparison fails), not std::fmin's NaN rules:
  // those are a libm call each, which cost more than the rest of the walk.
  const auto lesser = [](float a, float b) { return b < a ? b : a; };
  const auto greater = [](float a, float b) { return a < b ? b : a; };
  // floor as an int, for coordinates held where converting them is defined (far outside the map
  // the walk clamps its texels into it anyway).
  const auto floor_index = [](float p) {
    p = p > -1e6f ? p : -1e6f;  // NaN too
    p = p < 1e6f ? p : 1e6f;
    const int i = static_cast<int>(p);
    return static_cast<float>(i) > p ? i - 1 : i;
  };
  const float back = back_, front = front_;
  if (!(front > back)) return front;
  const float range = front - back;
  const float size[2] = {static_cast<float>(width_), static_cast<float>(height_)};
  const float start[2] = {(u + gain_u * front) * size[0], (v + gain_v * front) * size[1]};
  const float speed[2] = {-gain_u * size[0], -gain_v * size[1]};
  const int first_x = std::clamp(floor_index(start[0]), 0, width_ - 1);
  const int first_y = std::clamp(floor_index(start[1]), 0, height_ - 1);
  const float fastest = greater(greater(std::fabs(speed[0]), std::fabs(speed[1])), 1.0e-30f);
  // A ray that does not move (a black pixel: no gain) meets the surface in the texel it starts in.
  if (!(fastest > 1.0e-30f)) return values_[static_cast<std::size_t>(first_y) * width_ + first_x];
  const float bound =
      bounds_[static_cast<std::size_t>(first_y / depth_bound_tile) * bound_width_ + first_x / depth_bound_tile];
  float t = lesser(lesser(front - bound, static_cast<float>(depth_bound_tile - 1) / fastest), range);
  int texel[2], step[2];
  float delta[2], next[2];
  for (int a = 0; a < 2; ++a) {
    const float p = start[a] + speed[a] * t;
    texel[a] = floor_index(p);
    const float below = static_cast<float>(texel[a]);
    step[a] = speed[a] > 0.f ? 1 : speed[a] < 0.f ? -1 : 0;
    delta[a] = 1.0f / greater(std::fabs(speed[a]), 1.0e-30f);
    next[a] = t + (speed[a] > 0.f ? below + 1.0f - p : p - below) * delta[a];
  }
  const float* values = values_.data();
  for (int i = 0; i < depth_search_texels; ++i) {
    const float t_next = lesser(lesser(next[0], next[1]), range);
    const float value = values[static_cast<std::size_t>(std::clamp(texel[1], 0, height_ - 1)) * width_ +
                               std::clamp(texel[0], 0, width_ - 1)];
    const float leave = t_next >= range ? back : front - t_next;
    if (value >= leave) return lesser(value, front - t);
    if (t_next >= range) break;
    const int a = next[0] < next[1] ? 0 : 1;
    texel[a] += step[a];
    t = next[a];
    next[a] += delta[a];
  }
  return back;
}

// The uv shift per unit of δ / W of a ray crossing the pupil plane at `pupil_mm`: (p_x / e, −p_y W / (e H)).
Vec2 pupil_gain(const DepthGeometry& g, Vec2 pupil_mm);

// Where the chief ray of display position s through lens centre c crosses the pupil plane.
inline Vec2 chief_ray_pupil_crossing(const EyeMapping& m, Vec2 s, Vec2 c) {
  const double k = m.eye_relief_mm / m.gap_mm;
  return {c.x - (s.x - c.x) * k, c.y - (s.y - c.y) * k};
}

}  // namespace nelf
