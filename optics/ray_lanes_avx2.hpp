#pragma once
// Eight rays of four floats (u, v, gain_u, gain_v: DisparitySurface::crossings' input, the CPU
// composite table's DepthRay) as four AVX2 registers of one field each, for the code that searches
// and taps eight rays at a time (optics/depth.cpp, compositor/cpu/composite_table.cpp). A 4×4
// transpose within each 128-bit half: four gathers cost several times more on some CPUs (AMD's
// Zen 2 among them). Only for x86-64 with GCC or Clang; the callers check the CPU (available()).
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

namespace nelf::avx2 {

// Whether this CPU runs AVX2 code (Debian's x86-64 baseline is SSE2): asked once.
inline bool available() {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
}

struct RayLanes {
  __m256 u, v, gain_u, gain_v;  // lanes hold rays 0 2 4 6 1 3 5 7 (ray_order)
};

__attribute__((target("avx2"), always_inline)) inline RayLanes load_rays(const float* rays) {
  const __m256 r0 = _mm256_loadu_ps(rays), r1 = _mm256_loadu_ps(rays + 8), r2 = _mm256_loadu_ps(rays + 16),
               r3 = _mm256_loadu_ps(rays + 24);
  const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
  const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
  return {_mm256_shuffle_ps(t0, t2, 0x44), _mm256_shuffle_ps(t0, t2, 0xee), _mm256_shuffle_ps(t1, t3, 0x44),
          _mm256_shuffle_ps(t1, t3, 0xee)};
}

// For _mm256_permutevar8x32_*: lane i of the result takes ray i from load_rays' order.
__attribute__((target("avx2"), always_inline)) inline __m256i ray_order() {
  return _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
}
// The other way: lane i takes the value of ray (0 2 4 6 1 3 5 7)[i] from data in ray order.
__attribute__((target("avx2"), always_inline)) inline __m256i lane_order() {
  return _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
}

}  // namespace nelf::avx2
#endif
