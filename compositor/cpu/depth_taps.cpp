#include "compositor/cpu/depth_taps.hpp"

#include <cstdint>
#include <cstring>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include "optics/ray_lanes_avx2.hpp"
#define NELF_DEPTH_TAPS_AVX2 1
#endif

namespace nelf {

CompositeTable::Tap depth_tap(const CompositeTable::DepthRay& ray, float hit, const DepthTapImage& image) {
  const int width = image.size[0];
  const auto axis = [](float coordinate, float scale, float offset, int size, int& lo) {
    float c = (coordinate * scale + offset) * static_cast<float>(size) - 0.5f;
    c = c > -1.f ? c : -1.f;
    c = c < static_cast<float>(size) ? c : static_cast<float>(size);
    const int i = static_cast<int>(c + 1.f) - 1;  // floor, c ≥ -1
    lo = i < 0 ? 0 : i < size - 1 ? i : size - 1;
    return i >= 0 && i < size - 1 ? c - static_cast<float>(i) : 0.f;
  };
  int lo_x, lo_y;
  const float fx = axis(ray.u + ray.gain_u * hit, image.scale[0], image.offset[0], width, lo_x);
  const float fy = axis(ray.v + ray.gain_v * hit, image.scale[1], image.offset[1], image.size[1], lo_y);
  const float e0 = (1.f - fx) * (1.f - fy), e1 = fx * (1.f - fy), e2 = (1.f - fx) * fy, e3 = fx * fy;
  const int w0 = static_cast<int>(e0 * 256.f + 0.5f), w1 = static_cast<int>(e1 * 256.f + 0.5f),
            w2 = static_cast<int>(e2 * 256.f + 0.5f), w3 = static_cast<int>(e3 * 256.f + 0.5f);
  // The largest product (the first of equals, as make_tap) takes what rounding left over.
  const int a = e1 > e0 ? 1 : 0, b = e3 > e2 ? 3 : 2;
  const float ea = a ? e1 : e0, eb = b == 3 ? e3 : e2;
  const int largest = eb > ea ? b : a;
  const int rest = 256 - (w0 + w1 + w2 + w3);
  // The four weights as one word (bytes in tap order), built in registers: writing a Tap's bytes
  // one by one and reading the Tap back as 8 bytes stalls on store forwarding.
  const std::uint32_t word = static_cast<std::uint32_t>(w0) | static_cast<std::uint32_t>(w1) << 8 |
                             static_cast<std::uint32_t>(w2) << 16 | static_cast<std::uint32_t>(w3) << 24;
  const std::uint32_t fixed = word + (static_cast<std::uint32_t>(rest) << (8 * largest));
  // All the weight on one texel (its byte wrapped to 0 from 256): that texel's tap alone.
  const bool alone = (largest == 0 ? w0 : largest == 1 ? w1 : largest == 2 ? w2 : w3) + rest == 256;
  const std::int32_t offset = largest == 0 ? 0 : largest == 1 ? 1 : largest == 2 ? width : width + 1;
  CompositeTable::Tap tap;
  tap.texel = lo_y * width + lo_x + (alone ? offset : 0);
  const std::uint32_t weights = alone ? 0u : fixed;
  std::memcpy(tap.weights.data(), &weights, 4);
  return tap;
}

namespace {

#if defined(NELF_DEPTH_TAPS_AVX2)
// One axis of depth_tap() for eight coordinates: the clamped first texel and the fraction towards
// the next (0 where they coincide).
__attribute__((target("avx2"), always_inline)) inline __m256 depth_tap_axis(__m256 coordinate, float scale,
                                                                            float offset, int size, __m256i& lo) {
  const __m256 size_f = _mm256_set1_ps(static_cast<float>(size));
  __m256 c = _mm256_sub_ps(
      _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(coordinate, _mm256_set1_ps(scale)), _mm256_set1_ps(offset)), size_f),
      _mm256_set1_ps(0.5f));
  c = _mm256_max_ps(c, _mm256_set1_ps(-1.f));  // NaN to -1, as c > -1 ? c : -1
  c = _mm256_min_ps(c, size_f);                // as c < size ? c : size
  const __m256i i = _mm256_sub_epi32(_mm256_cvttps_epi32(_mm256_add_ps(c, _mm256_set1_ps(1.f))), _mm256_set1_epi32(1));
  const __m256i zero = _mm256_setzero_si256(), last = _mm256_set1_epi32(size - 1);
  lo = _mm256_min_epi32(_mm256_max_epi32(i, zero), last);
  const __m256i inside = _mm256_andnot_si256(_mm256_cmpgt_epi32(zero, i), _mm256_cmpgt_epi32(last, i));
  return _mm256_and_ps(_mm256_sub_ps(c, _mm256_cvtepi32_ps(i)), _mm256_castsi256_ps(inside));
}
// A product's 8-bit weight, rounded half up (e ≥ 0).
__attribute__((target("avx2"), always_inline)) inline __m256i depth_tap_weight(__m256 e) {
  return _mm256_cvttps_epi32(_mm256_add_ps(_mm256_mul_ps(e, _mm256_set1_ps(256.f)), _mm256_set1_ps(0.5f)));
}

// depth_tap() for eight rays a register, black rays (u < -1e8) the `black` texel alone; writes
// count / 8 * 8 taps and returns how many.
__attribute__((target("avx2"))) int depth_taps_avx2(const CompositeTable::DepthRay* rays, const float* hits, int count,
                                                    const DepthTapImage& image, std::int32_t black,
                                                    CompositeTable::Tap* out) {
  const int width = image.size[0], height = image.size[1];
  const std::array<float, 2> scale = image.scale, offsets = image.offset;
  const __m256 one = _mm256_set1_ps(1.f);
  const __m256i w_vector = _mm256_set1_epi32(width);
  int x = 0;
  for (; x + 8 <= count; x += 8) {
    // In load_rays' lane order; the taps go back into ray order before they are stored.
    const auto [u, v, gain_u, gain_v] = avx2::load_rays(&rays[x].u);
    const __m256 hit = _mm256_permutevar8x32_ps(_mm256_loadu_ps(hits + x), avx2::lane_order());
    __m256i lo_x, lo_y;
    const __m256 fx = depth_tap_axis(_mm256_add_ps(u, _mm256_mul_ps(gain_u, hit)), scale[0], offsets[0], width, lo_x);
    const __m256 fy = depth_tap_axis(_mm256_add_ps(v, _mm256_mul_ps(gain_v, hit)), scale[1], offsets[1], height, lo_y);
    const __m256 gx = _mm256_sub_ps(one, fx), gy = _mm256_sub_ps(one, fy);
    const __m256 e0 = _mm256_mul_ps(gx, gy), e1 = _mm256_mul_ps(fx, gy), e2 = _mm256_mul_ps(gx, fy),
                 e3 = _mm256_mul_ps(fx, fy);
    const __m256i w0 = depth_tap_weight(e0), w1 = depth_tap_weight(e1), w2 = depth_tap_weight(e2),
                  w3 = depth_tap_weight(e3);
    // The largest (the first of equals): a of the first pair, b of the second, then between them.
    const __m256 a_is_1 = _mm256_cmp_ps(e1, e0, _CMP_GT_OQ), b_is_3 = _mm256_cmp_ps(e3, e2, _CMP_GT_OQ);
    const __m256 ea = _mm256_blendv_ps(e0, e1, a_is_1), eb = _mm256_blendv_ps(e2, e3, b_is_3);
    const __m256 b_wins = _mm256_cmp_ps(eb, ea, _CMP_GT_OQ);
    const __m256i a = _mm256_and_si256(_mm256_castps_si256(a_is_1), _mm256_set1_epi32(1));
    const __m256i b =
        _mm256_add_epi32(_mm256_set1_epi32(2), _mm256_and_si256(_mm256_castps_si256(b_is_3), _mm256_set1_epi32(1)));
    const __m256i largest =
        _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(a), _mm256_castsi256_ps(b), b_wins));
    const __m256i wa = _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(w0), _mm256_castsi256_ps(w1), a_is_1));
    const __m256i wb = _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(w2), _mm256_castsi256_ps(w3), b_is_3));
    const __m256i w_largest =
        _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(wa), _mm256_castsi256_ps(wb), b_wins));
    const __m256i rest =
        _mm256_sub_epi32(_mm256_set1_epi32(256), _mm256_add_epi32(_mm256_add_epi32(w0, w1), _mm256_add_epi32(w2, w3)));
    const __m256i word = _mm256_or_si256(_mm256_or_si256(w0, _mm256_slli_epi32(w1, 8)),
                                         _mm256_or_si256(_mm256_slli_epi32(w2, 16), _mm256_slli_epi32(w3, 24)));
    const __m256i fixed = _mm256_add_epi32(word, _mm256_sllv_epi32(rest, _mm256_slli_epi32(largest, 3)));
    const __m256i alone = _mm256_cmpeq_epi32(_mm256_add_epi32(w_largest, rest), _mm256_set1_epi32(256));
    // The offset of texel `largest` from the first: 0, 1, a row, a row and one.
    const __m256i offset = _mm256_add_epi32(_mm256_and_si256(largest, _mm256_set1_epi32(1)),
                                            _mm256_mullo_epi32(_mm256_srli_epi32(largest, 1), w_vector));
    __m256i texel =
        _mm256_add_epi32(_mm256_add_epi32(_mm256_mullo_epi32(lo_y, w_vector), lo_x), _mm256_and_si256(offset, alone));
    __m256i weights = _mm256_andnot_si256(alone, fixed);
    const __m256i dark = _mm256_castps_si256(_mm256_cmp_ps(u, _mm256_set1_ps(-1.0e8f), _CMP_LT_OQ));
    texel = _mm256_blendv_epi8(texel, _mm256_set1_epi32(black), dark);
    weights = _mm256_andnot_si256(dark, weights);
    texel = _mm256_permutevar8x32_epi32(texel, avx2::ray_order());
    weights = _mm256_permutevar8x32_epi32(weights, avx2::ray_order());
    // Interleaved as taps (texel, weights): lanes 0 1 4 5 in `low`, 2 3 6 7 in `high`.
    const __m256i low = _mm256_unpacklo_epi32(texel, weights), high = _mm256_unpackhi_epi32(texel, weights);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + x), _mm256_permute2x128_si256(low, high, 0x20));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + x + 4), _mm256_permute2x128_si256(low, high, 0x31));
  }
  return x;
}
#endif

}  // namespace

void depth_taps(const CompositeTable::DepthRay* rays, const float* hits, int count, const DepthTapImage& image,
                CompositeTable::Tap black, CompositeTable::Tap* out) {
  int x = 0;
#if defined(NELF_DEPTH_TAPS_AVX2)
  if (avx2::available()) x = depth_taps_avx2(rays, hits, count, image, black.texel, out);
#endif
  for (; x < count; ++x) out[x] = rays[x].u < -1.0e8f ? black : depth_tap(rays[x], hits[x], image);
}

}  // namespace nelf
