#include "optics/depth.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace nelf {

DepthGeometry depth_geometry(const Profile& profile, const EyeMapping& mapping) {
  return {mapping.render_distance_mm, mapping.screen_size_mm, profile.viewing.ipd_mm};
}

double disparity_mm_from_depth(const DepthGeometry& g, double depth_mm) {
  return g.ipd_mm * (g.screen_distance_mm / depth_mm - 1.0);
}

double depth_mm_from_disparity(const DepthGeometry& g, double disparity_mm) {
  const double inverse = (1.0 + disparity_mm / g.ipd_mm) / g.screen_distance_mm;
  return inverse > 0.0 ? 1.0 / inverse : std::numeric_limits<double>::infinity();
}

Vec2 pupil_gain(const DepthGeometry& g, Vec2 pupil_mm) {
  return {pupil_mm.x / g.ipd_mm, -pupil_mm.y * g.screen_size_mm.x / (g.ipd_mm * g.screen_size_mm.y)};
}

DisparitySurface::DisparitySurface(const ViewDisparity& disparity)
    : width_(disparity.width), height_(disparity.height) {
  if (width_ <= 0 || height_ <= 0 ||
      disparity.d.size() != static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_))
    throw std::invalid_argument(
        fmt::format("disparity map of {}x{} with {} values", width_, height_, disparity.d.size()));
  values_.resize(disparity.d.size());
  const float to_screen = 1.0f / static_cast<float>(width_);  // map pixels to fractions of the screen's width
  bool any = false;
  for (int y = 0; y < height_; ++y) {
    const float* in = disparity.d.data() + static_cast<std::size_t>(y) * width_;
    float* out = values_.data() + static_cast<std::size_t>(y) * width_;
    // An unknown run is what one view sees and the other does not (an occlusion beside a nearer
    // surface, or the view's edge): it belongs to the farther of the known texels either side of it
    // in the row (the smaller disparity), or to the one there is at the row's ends.
    std::vector<float> before(static_cast<std::size_t>(width_), std::numeric_limits<float>::quiet_NaN());
    float last = std::numeric_limits<float>::quiet_NaN();
    for (int x = 0; x < width_; ++x) {
      if (std::isfinite(in[x])) last = in[x];
      before[static_cast<std::size_t>(x)] = last;
    }
    last = std::numeric_limits<float>::quiet_NaN();
    for (int x = width_ - 1; x >= 0; --x) {
      if (std::isfinite(in[x])) {
        last = in[x];
        out[x] = in[x] * to_screen;
        any = true;
        continue;
      }
      const float left = before[static_cast<std::size_t>(x)];
      const float farther = std::isnan(left) ? last : std::isnan(last) ? left : std::min(left, last);
      out[x] = std::isnan(farther) ? 0.f : farther * to_screen;  // a row with nothing known: the screen
    }
  }
  unknown_ = !any;
  const auto [lo, hi] = std::minmax_element(values_.begin(), values_.end());
  back_ = *lo;
  front_ = *hi;
  // Each tile's largest value, then the largest of its 3 × 3 tiles.
  constexpr int tile = depth_bound_tile;
  bound_width_ = (width_ + tile - 1) / tile;
  bound_height_ = (height_ + tile - 1) / tile;
  const auto at_tile = [&](int tx, int ty) { return static_cast<std::size_t>(ty) * bound_width_ + tx; };
  std::vector<float> tile_front(static_cast<std::size_t>(bound_width_) * bound_height_, back_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      float& m = tile_front[at_tile(x / tile, y / tile)];
      m = std::max(m, values_[static_cast<std::size_t>(y) * width_ + x]);
    }
  bounds_.assign(tile_front.size(), back_);
  for (int ty = 0; ty < bound_height_; ++ty)
    for (int tx = 0; tx < bound_width_; ++tx)
      for (int ny = std::max(ty - 1, 0); ny <= std::min(ty + 1, bound_height_ - 1); ++ny)
        for (int nx = std::max(tx - 1, 0); nx <= std::min(tx + 1, bound_width_ - 1); ++nx)
          bounds_[at_tile(tx, ty)] = std::max(bounds_[at_tile(tx, ty)], tile_front[at_tile(nx, ny)]);
}

float DisparitySurface::at(Vec2 uv) const {
  const int x = std::clamp(static_cast<int>(std::floor(uv.x * width_)), 0, width_ - 1);
  const int y = std::clamp(static_cast<int>(std::floor(uv.y * height_)), 0, height_ - 1);
  return values_[static_cast<std::size_t>(y) * width_ + x];
}

Vec2 DisparitySurface::hit(Vec2 flat_uv, Vec2 gain) const {
  const auto along = [&](double d) { return Vec2{flat_uv.x + gain.x * d, flat_uv.y + gain.y * d}; };
  const double front = front_, back = back_;
  if (!(front > back)) return along(front);
  // A texel walk (Amanatides and Woo's): t = front − δ / W runs from 0 to the range; p is the ray's
  // texel coordinate at the front, v how many texels it moves per unit of t along each axis.
  const double range = front - back;
  const Vec2 at_front = along(front);
  const double start[2] = {at_front.x * width_, at_front.y * height_};
  const double v[2] = {-gain.x * width_, -gain.y * height_};
  // The skip: until the ray falls to its tile's bound, or has moved depth_bound_tile − 1 texels
  // along an axis (a texel index moves by at most as much: the bound still holds), it is in front
  // of every texel it crosses. Out of the map its texels are the edge's (clamped), no farther away.
  const int size[2] = {width_, height_};
  int tile[2];
  for (int a = 0; a < 2; ++a)
    tile[a] = std::clamp(static_cast<int>(std::floor(start[a])), 0, size[a] - 1) / depth_bound_tile;
  const double bound = bounds_[static_cast<std::size_t>(tile[1]) * bound_width_ + tile[0]];
  const double fastest = std::max({std::abs(v[0]), std::abs(v[1]), 1e-30});
  double t = std::min({front - bound, (depth_bound_tile - 1) / fastest, range});
  const double p[2] = {start[0] + v[0] * t, start[1] + v[1] * t};
  int texel[2], step[2];
  double delta[2], next[2];
  for (int a = 0; a < 2; ++a) {
    texel[a] = static_cast<int>(std::floor(p[a]));
    step[a] = v[a] > 0.0 ? 1 : v[a] < 0.0 ? -1 : 0;
    const double speed = std::max(std::abs(v[a]), 1e-30);
    delta[a] = 1.0 / speed;
    next[a] = t + (v[a] > 0.0 ? std::floor(p[a]) + 1.0 - p[a] : p[a] - std::floor(p[a])) / speed;
  }
  for (int i = 0; i < depth_search_texels; ++i) {
    const double t_next = std::min({next[0], next[1], range});
    const double value = values_[static_cast<std::size_t>(std::clamp(texel[1], 0, height_ - 1)) * width_ +
                                 std::clamp(texel[0], 0, width_ - 1)];
    const double leave = t_next >= range ? back : front - t_next;
    if (value >= leave) return along(std::min(value, front - t));
    if (t_next >= range) break;
    const int a = next[0] < next[1] ? 0 : 1;
    texel[a] += step[a];
    t = next[a];
    next[a] += delta[a];
  }
  return along(back);
}

}  // namespace nelf
