#include "inputs/yuv_block_means.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace nelf {

YuvToRgb yuv_to_rgb_from_sws(const int coefficients[4], bool full_range) {
  // swscale's table is for limited-range chroma (224 codes for the full swing). Full-range input
  // has 255 codes for the swing: the same colour needs 224/255 of the coefficient.
  const float chroma = full_range ? 224.f / 255.f : 1.f;
  const float crv = coefficients[0] / 65536.f * chroma, cbu = coefficients[1] / 65536.f * chroma;
  const float cgu = coefficients[2] / 65536.f * chroma, cgv = coefficients[3] / 65536.f * chroma;
  const float luma = full_range ? 1.f : 255.f / 219.f;
  YuvToRgb t;
  t.y_offset = full_range ? 0.f : 16.f;
  const float m[3][3] = {{luma, 0.f, crv}, {luma, -cgu, -cgv}, {luma, cbu, 0.f}};
  std::copy(&m[0][0], &m[0][0] + 9, &t.m[0][0]);
  return t;
}

bool yuv420_block_means_supported(int block_x, int block_y) {
  return block_x >= 2 && block_y >= 2 && block_x % 2 == 0 && block_y % 2 == 0 && block_x <= 128 && block_y <= 128;
}

namespace {

// The sum of `rows` rows of `width` bytes, column by column (≤ 128 rows: fits signed 16 bits, as
// _mm_madd_epi16 below takes them). SSE2 sixteen columns at a time: GCC 12 at -O2 leaves the
// plain loop scalar.
void sum_rows(const std::uint8_t* first, std::ptrdiff_t stride, int rows, int width, std::int16_t* sums) {
  int x = 0;
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128();
  for (; x + 16 <= width; x += 16) {
    __m128i lo = zero, hi = zero;
    for (int r = 0; r < rows; ++r) {
      const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(first + r * stride + x));
      lo = _mm_add_epi16(lo, _mm_unpacklo_epi8(bytes, zero));
      hi = _mm_add_epi16(hi, _mm_unpackhi_epi8(bytes, zero));
    }
    _mm_storeu_si128(reinterpret_cast<__m128i*>(sums + x), lo);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(sums + x + 8), hi);
  }
#endif
  for (; x < width; ++x) {
    int s = 0;
    for (int r = 0; r < rows; ++r) s += first[r * stride + x];
    sums[x] = static_cast<std::int16_t>(s);
  }
}

// Adds up `block` neighbouring columns of `sums` for each of `outputs`.
void sum_columns(const std::int16_t* sums, int outputs, int block, std::int32_t* out) {
  int o = 0;
#if defined(__SSE2__)
  if (block == 1) {  // chroma of 2-pixel-wide blocks: widen only
    for (; o + 8 <= outputs; o += 8) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(sums + o));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + o), _mm_unpacklo_epi16(v, _mm_setzero_si128()));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + o + 4), _mm_unpackhi_epi16(v, _mm_setzero_si128()));
    }
  } else if (block == 2) {  // the usual luma case (half side-by-side 1080p: 2×4 blocks): pairs in one madd
    const __m128i ones = _mm_set1_epi16(1);
    for (; o + 4 <= outputs; o += 4)
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + o),
                       _mm_madd_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(sums + 2 * o)), ones));
  }
#endif
  for (; o < outputs; ++o) {
    std::int32_t s = 0;
    for (int k = 0; k < block; ++k) s += sums[o * block + k];
    out[o] = s;
  }
}

std::uint8_t to_code(float value) { return static_cast<std::uint8_t>(std::clamp(value, 0.f, 255.f) + 0.5f); }

// The sum of `rows` rows of `width` deep samples, column by column, in 32 bits.
void sum_rows(const std::uint16_t* first, std::ptrdiff_t stride, int rows, int width, std::int32_t* sums) {
  int x = 0;
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128();
  for (; x + 8 <= width; x += 8) {
    __m128i lo = zero, hi = zero;
    for (int r = 0; r < rows; ++r) {
      const __m128i samples = _mm_loadu_si128(reinterpret_cast<const __m128i*>(first + r * stride + x));
      lo = _mm_add_epi32(lo, _mm_unpacklo_epi16(samples, zero));
      hi = _mm_add_epi32(hi, _mm_unpackhi_epi16(samples, zero));
    }
    _mm_storeu_si128(reinterpret_cast<__m128i*>(sums + x), lo);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(sums + x + 4), hi);
  }
#endif
  for (; x < width; ++x) {
    std::int32_t s = 0;
    for (int r = 0; r < rows; ++r) s += first[r * stride + x];
    sums[x] = s;
  }
}

void sum_columns(const std::int32_t* sums, int outputs, int block, std::int32_t* out) {
  for (int o = 0; o < outputs; ++o) {
    std::int32_t s = 0;
    for (int k = 0; k < block; ++k) s += sums[o * block + k];
    out[o] = s;
  }
}

// One row of output pixels from the block sums (Y: y_scale × sum is the mean; U, V likewise), each
// channel rounded after `dither[o]` (in −0.5..0.5 codes; null: none) is added.
void convert_row(const std::int32_t* y_sum, const std::int32_t* u_sum, const std::int32_t* v_sum, int outputs,
                 float y_scale, float c_scale, const YuvToRgb& matrix, std::uint8_t* out,
                 const float* dither = nullptr) {
  const auto& m = matrix.m;
  int o = 0;
#if defined(__SSE2__)
  const __m128 ys = _mm_set1_ps(y_scale), cs = _mm_set1_ps(c_scale), y0 = _mm_set1_ps(matrix.y_offset),
               c0 = _mm_set1_ps(128.f);
  const __m128i alpha = _mm_set1_epi32(255);
  for (; o + 4 <= outputs; o += 4) {
    const auto load = [](const std::int32_t* p) {
      return _mm_cvtepi32_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
    };
    const __m128 y = _mm_sub_ps(_mm_mul_ps(load(y_sum + o), ys), y0);
    const __m128 u = _mm_sub_ps(_mm_mul_ps(load(u_sum + o), cs), c0);
    const __m128 v = _mm_sub_ps(_mm_mul_ps(load(v_sum + o), cs), c0);
    const __m128 offset = dither ? _mm_loadu_ps(dither + o) : _mm_setzero_ps();
    const auto channel = [&](const float* k) {
      const __m128 value = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(k[0]), y), _mm_mul_ps(_mm_set1_ps(k[1]), u)),
                                      _mm_mul_ps(_mm_set1_ps(k[2]), v));
      return _mm_cvtps_epi32(_mm_add_ps(value, offset));  // nearest; the packs below clamp to 0..255
    };
    const __m128i r = channel(m[0]), g = channel(m[1]), b = channel(m[2]);
    // r0 r1 r2 r3 / g… / b… → r0 g0 b0 a0 r1 …
    const __m128i rb_lo = _mm_unpacklo_epi32(r, b), rb_hi = _mm_unpackhi_epi32(r, b);
    const __m128i ga_lo = _mm_unpacklo_epi32(g, alpha), ga_hi = _mm_unpackhi_epi32(g, alpha);
    const __m128i p01 = _mm_packs_epi32(_mm_unpacklo_epi32(rb_lo, ga_lo), _mm_unpackhi_epi32(rb_lo, ga_lo));
    const __m128i p23 = _mm_packs_epi32(_mm_unpacklo_epi32(rb_hi, ga_hi), _mm_unpackhi_epi32(rb_hi, ga_hi));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 4 * o), _mm_packus_epi16(p01, p23));
  }
#endif
  for (; o < outputs; ++o) {
    const float y = static_cast<float>(y_sum[o]) * y_scale - matrix.y_offset;
    const float u = static_cast<float>(u_sum[o]) * c_scale - 128.f;
    const float v = static_cast<float>(v_sum[o]) * c_scale - 128.f;
    const float d = dither ? dither[o] : 0.f;
    out[4 * o + 0] = to_code(m[0][0] * y + m[0][1] * u + m[0][2] * v + d);
    out[4 * o + 1] = to_code(m[1][0] * y + m[1][1] * u + m[1][2] * v + d);
    out[4 * o + 2] = to_code(m[2][0] * y + m[2][1] * u + m[2][2] * v + d);
    out[4 * o + 3] = 255;
  }
}

}  // namespace

namespace {

// Both depths: each output row's block sums (16 bits a column for 8-bit samples, 32 for deeper),
// their means (`scale` takes the samples to 8-bit code values), converted; `dithered`: with the
// 4×4 ordered dither.
template <typename Planes>
void block_means(const Planes& planes, int width, int height, int block_x, int block_y, const YuvToRgb& matrix,
                 float scale, bool dithered, std::uint8_t* out, std::size_t out_stride) {
  using RowSum = std::conditional_t<sizeof(*planes.y) == 1, std::int16_t, std::int32_t>;
  const int out_w = width / block_x, out_h = height / block_y;
  const int chroma_w = width / 2, chroma_bx = block_x / 2, chroma_by = block_y / 2;
  std::vector<RowSum> y_rows(static_cast<std::size_t>(width)), u_rows(static_cast<std::size_t>(chroma_w)),
      v_rows(static_cast<std::size_t>(chroma_w));
  std::vector<std::int32_t> y_sum(static_cast<std::size_t>(out_w)), u_sum(static_cast<std::size_t>(out_w)),
      v_sum(static_cast<std::size_t>(out_w));
  const float y_scale = scale / static_cast<float>(block_x * block_y);
  const float c_scale = scale / static_cast<float>(chroma_bx * chroma_by);
  // The 4×4 Bayer matrix, as offsets in −0.5..0.5 of a code, one row of them per output row mod 4.
  static constexpr int kBayer[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};
  std::vector<float> dither[4];
  if (dithered)
    for (int r = 0; r < 4; ++r) {
      dither[r].resize(static_cast<std::size_t>(out_w));
      for (int o = 0; o < out_w; ++o) dither[r][static_cast<std::size_t>(o)] = (kBayer[r][o % 4] + 0.5f) / 16.f - 0.5f;
    }
  for (int oy = 0; oy < out_h; ++oy) {
    sum_rows(planes.y + static_cast<std::ptrdiff_t>(oy) * block_y * planes.y_stride, planes.y_stride, block_y, width,
             y_rows.data());
    sum_rows(planes.u + static_cast<std::ptrdiff_t>(oy) * chroma_by * planes.u_stride, planes.u_stride, chroma_by,
             chroma_w, u_rows.data());
    sum_rows(planes.v + static_cast<std::ptrdiff_t>(oy) * chroma_by * planes.v_stride, planes.v_stride, chroma_by,
             chroma_w, v_rows.data());
    sum_columns(y_rows.data(), out_w, block_x, y_sum.data());
    sum_columns(u_rows.data(), out_w, chroma_bx, u_sum.data());
    sum_columns(v_rows.data(), out_w, chroma_bx, v_sum.data());
    convert_row(y_sum.data(), u_sum.data(), v_sum.data(), out_w, y_scale, c_scale, matrix,
                out + static_cast<std::size_t>(oy) * out_stride, dithered ? dither[oy % 4].data() : nullptr);
  }
}

}  // namespace

void yuv420_block_means(const Yuv420Planes& planes, int width, int height, int block_x, int block_y,
                        const YuvToRgb& matrix, std::uint8_t* out, std::size_t out_stride) {
  block_means(planes, width, height, block_x, block_y, matrix, 1.f, false, out, out_stride);
}

void yuv420_block_means(const Yuv420Planes16& planes, int width, int height, int block_x, int block_y,
                        const YuvToRgb& matrix, std::uint8_t* out, std::size_t out_stride) {
  // Means in 8-bit code values, at full precision, dithered.
  block_means(planes, width, height, block_x, block_y, matrix, 1.f / static_cast<float>(1 << (planes.bits - 8)), true,
              out, out_stride);
}

}  // namespace nelf
