#include "hmz_output/rgba_to_yuv.hpp"

#include <algorithm>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace nelf {

namespace {

// BT.709 from full-range R'G'B' (0-255) to limited-range Y'CbCr: Y' = 16 + 219/255 · (Kr R + Kg G +
// Kb B), Cb = 128 + 224/255 · (B − Y)/(2 (1 − Kb)), Cr = 128 + 224/255 · (R − Y)/(2 (1 − Kr)).
// Fixed point: luma coefficients × 2^15 on single pixels; chroma coefficients × 2^13 on sums of
// the four pixels of a 2×2 block (= mean × 2^15). Both fit pmaddwd's signed 16 bits.
constexpr double kr = 0.2126, kb = 0.0722, kg = 1.0 - kr - kb;
constexpr double luma_range = 219.0 / 255.0, chroma_range = 224.0 / 255.0;
constexpr int fixed(double x, double scale) { return static_cast<int>(x * scale + (x < 0 ? -0.5 : 0.5)); }
constexpr int YR = fixed(kr * luma_range, 32768), YG = fixed(kg * luma_range, 32768),
              YB = fixed(kb * luma_range, 32768);
constexpr int UR = fixed(-kr / (2 * (1 - kb)) * chroma_range, 8192),
              UG = fixed(-kg / (2 * (1 - kb)) * chroma_range, 8192), UB = fixed(0.5 * chroma_range, 8192);
constexpr int VR = fixed(0.5 * chroma_range, 8192), VG = fixed(-kg / (2 * (1 - kr)) * chroma_range, 8192),
              VB = fixed(-kb / (2 * (1 - kr)) * chroma_range, 8192);
constexpr int luma_offset = (16 << 15) + (1 << 14), chroma_offset = (128 << 15) + (1 << 14);

std::uint8_t luma(const std::uint8_t* p) {
  return static_cast<std::uint8_t>((YR * p[0] + YG * p[1] + YB * p[2] + luma_offset) >> 15);
}
std::uint8_t chroma(const int sum[3], int r, int g, int b) {
  return static_cast<std::uint8_t>(std::clamp((r * sum[0] + g * sum[1] + b * sum[2] + chroma_offset) >> 15, 0, 255));
}

// Luma of pixels [from, width) of one row, one at a time.
void luma_row(const std::uint8_t* rgba, int from, int width, std::uint8_t* y) {
  for (int x = from; x < width; ++x) y[x] = luma(rgba + 4 * x);
}

// Cb and Cr of chroma samples [from, ⌈width/2⌉) from rows `top` and `bottom`, one at a time.
void chroma_row(const std::uint8_t* top, const std::uint8_t* bottom, int from, int width, std::uint8_t* u,
                std::uint8_t* v) {
  for (int cx = from; 2 * cx < width; ++cx) {
    const int left = 2 * cx, right = std::min(2 * cx + 1, width - 1);
    int sum[3];
    for (int c = 0; c < 3; ++c)
      sum[c] = top[4 * left + c] + top[4 * right + c] + bottom[4 * left + c] + bottom[4 * right + c];
    u[cx] = chroma(sum, UR, UG, UB);
    v[cx] = chroma(sum, VR, VG, VB);
  }
}

#if defined(__SSE2__)
// Σ over each pixel's R, G, B of channel × coefficient (`madd` of unpacked pixels), for the four
// pixels of `low` (pixels 0, 1) and `high` (pixels 2, 3): [pixel 0, 1, 2, 3] as int32.
__m128i dot4(__m128i low, __m128i high, __m128i coefficients) {
  const __m128 a = _mm_castsi128_ps(_mm_madd_epi16(low, coefficients));
  const __m128 b = _mm_castsi128_ps(_mm_madd_epi16(high, coefficients));
  return _mm_add_epi32(_mm_castps_si128(_mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0))),
                       _mm_castps_si128(_mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1))));
}

// Luma of 4 pixels at `p`, as int32.
__m128i luma4(const std::uint8_t* p, __m128i coefficients) {
  const __m128i zero = _mm_setzero_si128();
  const __m128i pixels = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
  const __m128i sum = dot4(_mm_unpacklo_epi8(pixels, zero), _mm_unpackhi_epi8(pixels, zero), coefficients);
  return _mm_srai_epi32(_mm_add_epi32(sum, _mm_set1_epi32(luma_offset)), 15);
}

// Luma of pixels [0, width rounded down to 16); returns where it stopped.
int luma_row_sse2(const std::uint8_t* rgba, int width, std::uint8_t* y) {
  const __m128i coefficients = _mm_setr_epi16(YR, YG, YB, 0, YR, YG, YB, 0);
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    const std::uint8_t* p = rgba + 4 * x;
    const __m128i a = _mm_packs_epi32(luma4(p, coefficients), luma4(p + 16, coefficients));
    const __m128i b = _mm_packs_epi32(luma4(p + 32, coefficients), luma4(p + 48, coefficients));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(y + x), _mm_packus_epi16(a, b));
  }
  return x;
}

// The RGBA sums of two 2×2 blocks: pixels 0-3 of `top` and `bottom` → [block 0, block 1] as int16.
__m128i block_sums(__m128i top, __m128i bottom) {
  const __m128i zero = _mm_setzero_si128();
  const __m128i low = _mm_add_epi16(_mm_unpacklo_epi8(top, zero), _mm_unpacklo_epi8(bottom, zero));
  const __m128i high = _mm_add_epi16(_mm_unpackhi_epi8(top, zero), _mm_unpackhi_epi8(bottom, zero));
  return _mm_unpacklo_epi64(_mm_add_epi16(low, _mm_srli_si128(low, 8)), _mm_add_epi16(high, _mm_srli_si128(high, 8)));
}

// Four chroma samples' bytes from the block sums of blocks 0-1 and 2-3.
int chroma4(__m128i blocks01, __m128i blocks23, __m128i coefficients) {
  __m128i c = _mm_srai_epi32(_mm_add_epi32(dot4(blocks01, blocks23, coefficients), _mm_set1_epi32(chroma_offset)), 15);
  c = _mm_packs_epi32(c, c);
  return _mm_cvtsi128_si32(_mm_packus_epi16(c, c));
}

// Chroma samples [0, width/8·4) from rows `top` and `bottom`; returns where it stopped.
int chroma_row_sse2(const std::uint8_t* top, const std::uint8_t* bottom, int width, std::uint8_t* u, std::uint8_t* v) {
  const __m128i u_coefficients = _mm_setr_epi16(UR, UG, UB, 0, UR, UG, UB, 0);
  const __m128i v_coefficients = _mm_setr_epi16(VR, VG, VB, 0, VR, VG, VB, 0);
  int cx = 0;
  for (; 2 * cx + 8 <= width; cx += 4) {
    const auto load = [](const std::uint8_t* p) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p)); };
    const std::uint8_t *t = top + 8 * cx, *b = bottom + 8 * cx;
    const __m128i blocks01 = block_sums(load(t), load(b)), blocks23 = block_sums(load(t + 16), load(b + 16));
    const int us = chroma4(blocks01, blocks23, u_coefficients), vs = chroma4(blocks01, blocks23, v_coefficients);
    std::copy_n(reinterpret_cast<const std::uint8_t*>(&us), 4, u + cx);
    std::copy_n(reinterpret_cast<const std::uint8_t*>(&vs), 4, v + cx);
  }
  return cx;
}
#endif

}  // namespace

void rgba_to_yuv420_bt709(const std::uint8_t* rgba, std::ptrdiff_t rgba_stride, int width, int height,
                          const YuvPlanes& out) {
  for (int y = 0; y < height; y += 2) {
    const std::uint8_t* top = rgba + y * rgba_stride;
    const std::uint8_t* bottom = y + 1 < height ? top + rgba_stride : top;
    int luma_done = 0, chroma_done = 0;
#if defined(__SSE2__)
    luma_done = luma_row_sse2(top, width, out.y + y * out.y_stride);
    if (y + 1 < height) luma_row_sse2(bottom, width, out.y + (y + 1) * out.y_stride);
    chroma_done = chroma_row_sse2(top, bottom, width, out.u + (y / 2) * out.u_stride, out.v + (y / 2) * out.v_stride);
#endif
    luma_row(top, luma_done, width, out.y + y * out.y_stride);
    if (y + 1 < height) luma_row(bottom, luma_done, width, out.y + (y + 1) * out.y_stride);
    chroma_row(top, bottom, chroma_done, width, out.u + (y / 2) * out.u_stride, out.v + (y / 2) * out.v_stride);
  }
}

}  // namespace nelf
