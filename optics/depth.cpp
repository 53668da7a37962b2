#include "optics/depth.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include "optics/ray_lanes_avx2.hpp"
#define NELF_DEPTH_AVX2 1
#endif

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
  int first[2];
  for (int a = 0; a < 2; ++a)
    first[a] = std::clamp(static_cast<int>(std::floor(std::clamp(start[a], -1e9, 1e9))), 0, size[a] - 1);
  const double fastest = std::max({std::abs(v[0]), std::abs(v[1]), 1e-30});
  // A ray that does not move meets the surface in the texel it starts in (walking, it would never
  // leave it).
  if (!(fastest > 1e-30)) return along(values_[static_cast<std::size_t>(first[1]) * width_ + first[0]]);
  const double bound =
      bounds_[static_cast<std::size_t>(first[1] / depth_bound_tile) * bound_width_ + first[0] / depth_bound_tile];
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

#if defined(NELF_DEPTH_AVX2)
namespace {

// Floor as int32 lanes, NaN to the low end (max returns its second operand then), held where the
// conversion is defined.
__attribute__((target("avx2"), always_inline)) inline __m256i floor_index(__m256 p) {
  p = _mm256_min_ps(_mm256_max_ps(p, _mm256_set1_ps(-1e6f)), _mm256_set1_ps(1e6f));
  return _mm256_cvttps_epi32(_mm256_floor_ps(p));
}
__attribute__((target("avx2"), always_inline)) inline __m256i clamp_index(__m256i i, __m256i last) {
  return _mm256_min_epi32(_mm256_max_epi32(i, _mm256_setzero_si256()), last);
}

// crossing() for eight rays a register: the walk runs until every lane has crossed or left the
// range, a lane that is done keeping its result. Only AVX2 (no FMA): a fused multiply-add would
// round differently from the scalar search.
__attribute__((target("avx2"))) void crossings_avx2(const float* rays, int count, float* out, const float* values,
                                                    const float* bounds, int width, int height, int bound_width,
                                                    float front_value, float back_value) {
  static_assert(depth_bound_tile == 8, "a tile index is the texel index shifted right by 3");
  const __m256 front = _mm256_set1_ps(front_value), back = _mm256_set1_ps(back_value);
  const __m256 range = _mm256_sub_ps(front, back);
  const __m256 size_x = _mm256_set1_ps(static_cast<float>(width)), size_y = _mm256_set1_ps(static_cast<float>(height));
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.f), tiny = _mm256_set1_ps(1.0e-30f);
  const __m256 sign = _mm256_set1_ps(-0.f);
  const __m256i last_x = _mm256_set1_epi32(width - 1), last_y = _mm256_set1_epi32(height - 1);
  const __m256i row = _mm256_set1_epi32(width);
  int i = 0;
  for (; i + 8 <= count; i += 8) {
    const auto [u, v, gain_u, gain_v] = avx2::load_rays(rays + 4 * static_cast<std::size_t>(i));
    const __m256 start_x = _mm256_mul_ps(_mm256_add_ps(u, _mm256_mul_ps(gain_u, front)), size_x);
    const __m256 start_y = _mm256_mul_ps(_mm256_add_ps(v, _mm256_mul_ps(gain_v, front)), size_y);
    const __m256 speed_x = _mm256_mul_ps(_mm256_xor_ps(gain_u, sign), size_x);
    const __m256 speed_y = _mm256_mul_ps(_mm256_xor_ps(gain_v, sign), size_y);
    const __m256i first_x = clamp_index(floor_index(start_x), last_x);
    const __m256i first_y = clamp_index(floor_index(start_y), last_y);
    const __m256i tile_x = _mm256_srai_epi32(first_x, 3), tile_y = _mm256_srai_epi32(first_y, 3);
    const __m256 bound = _mm256_i32gather_ps(
        bounds, _mm256_add_epi32(_mm256_mullo_epi32(tile_y, _mm256_set1_epi32(bound_width)), tile_x), 4);
    const __m256 abs_x = _mm256_andnot_ps(sign, speed_x), abs_y = _mm256_andnot_ps(sign, speed_y);
    const __m256 fastest = _mm256_max_ps(_mm256_max_ps(abs_x, abs_y), tiny);
    // Rays that do not move (black pixels): the texel they start in, and no walk.
    const __m256 still = _mm256_cmp_ps(fastest, tiny, _CMP_LE_OQ);
    __m256 t =
        _mm256_min_ps(_mm256_min_ps(_mm256_sub_ps(front, bound),
                                    _mm256_div_ps(_mm256_set1_ps(static_cast<float>(depth_bound_tile - 1)), fastest)),
                      range);
    const __m256 p_x = _mm256_add_ps(start_x, _mm256_mul_ps(speed_x, t));
    const __m256 p_y = _mm256_add_ps(start_y, _mm256_mul_ps(speed_y, t));
    __m256i texel_x = floor_index(p_x), texel_y = floor_index(p_y);
    const __m256 below_x = _mm256_cvtepi32_ps(texel_x), below_y = _mm256_cvtepi32_ps(texel_y);
    const __m256 forward_x = _mm256_cmp_ps(speed_x, zero, _CMP_GT_OQ),
                 forward_y = _mm256_cmp_ps(speed_y, zero, _CMP_GT_OQ);
    const __m256 backward_x = _mm256_cmp_ps(speed_x, zero, _CMP_LT_OQ),
                 backward_y = _mm256_cmp_ps(speed_y, zero, _CMP_LT_OQ);
    // step: 1 forward, -1 backward, 0 still (the masks are all ones, i.e. -1, where true).
    const __m256i step_x = _mm256_sub_epi32(_mm256_castps_si256(backward_x), _mm256_castps_si256(forward_x));
    const __m256i step_y = _mm256_sub_epi32(_mm256_castps_si256(backward_y), _mm256_castps_si256(forward_y));
    const __m256 delta_x = _mm256_div_ps(one, _mm256_max_ps(abs_x, tiny));
    const __m256 delta_y = _mm256_div_ps(one, _mm256_max_ps(abs_y, tiny));
    __m256 next_x =
        _mm256_add_ps(t, _mm256_mul_ps(_mm256_blendv_ps(_mm256_sub_ps(p_x, below_x),
                                                        _mm256_sub_ps(_mm256_add_ps(below_x, one), p_x), forward_x),
                                       delta_x));
    __m256 next_y =
        _mm256_add_ps(t, _mm256_mul_ps(_mm256_blendv_ps(_mm256_sub_ps(p_y, below_y),
                                                        _mm256_sub_ps(_mm256_add_ps(below_y, one), p_y), forward_y),
                                       delta_y));
    __m256 result = back;
    if (_mm256_movemask_ps(still) != 0)
      result =
          _mm256_mask_i32gather_ps(back, values, _mm256_add_epi32(_mm256_mullo_epi32(first_y, row), first_x), still, 4);
    __m256 active = _mm256_andnot_ps(still, _mm256_castsi256_ps(_mm256_set1_epi32(-1)));
    for (int k = 0; k < depth_search_texels && _mm256_movemask_ps(active) != 0; ++k) {
      const __m256 t_next = _mm256_min_ps(_mm256_min_ps(next_x, next_y), range);
      const __m256i index =
          _mm256_add_epi32(_mm256_mullo_epi32(clamp_index(texel_y, last_y), row), clamp_index(texel_x, last_x));
      const __m256 value = _mm256_mask_i32gather_ps(zero, values, index, active, 4);
      const __m256 done = _mm256_cmp_ps(t_next, range, _CMP_GE_OQ);
      const __m256 leave = _mm256_blendv_ps(_mm256_sub_ps(front, t_next), back, done);
      const __m256 crossed = _mm256_and_ps(active, _mm256_cmp_ps(value, leave, _CMP_GE_OQ));
      result = _mm256_blendv_ps(result, _mm256_min_ps(value, _mm256_sub_ps(front, t)), crossed);
      active = _mm256_andnot_ps(_mm256_or_ps(crossed, done), active);
      // Along x where next_x < next_y, else along y.
      const __m256 along_x = _mm256_cmp_ps(next_x, next_y, _CMP_LT_OQ);
      const __m256i x_mask = _mm256_castps_si256(along_x);
      texel_x = _mm256_add_epi32(texel_x, _mm256_and_si256(step_x, x_mask));
      texel_y = _mm256_add_epi32(texel_y, _mm256_andnot_si256(x_mask, step_y));
      t = _mm256_blendv_ps(next_y, next_x, along_x);
      next_x = _mm256_blendv_ps(next_x, _mm256_add_ps(next_x, delta_x), along_x);
      next_y = _mm256_blendv_ps(_mm256_add_ps(next_y, delta_y), next_y, along_x);
    }
    _mm256_storeu_ps(out + i, _mm256_permutevar8x32_ps(result, avx2::ray_order()));
  }
}

}  // namespace
#endif

void DisparitySurface::crossings(const float* rays, int count, float* out) const {
  int i = 0;
#if defined(NELF_DEPTH_AVX2)
  if (avx2::available() && front_ > back_) {
    i = count / 8 * 8;
    crossings_avx2(rays, i, out, values_.data(), bounds_.data(), width_, height_, bound_width_, front_, back_);
  }
#endif
  for (; i < count; ++i) out[i] = crossing(rays[4 * i], rays[4 * i + 1], rays[4 * i + 2], rays[4 * i + 3]);
}

}  // namespace nelf
