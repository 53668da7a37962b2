#include "compositor/cpu/composite_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <future>
#include <stdexcept>

#include "compositor/cpu/depth_taps.hpp"
#include "optics/depth.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include "optics/ray_lanes_avx2.hpp"
#define NELF_TABLE_AVX2 1  // an AVX2 pass 1 where the CPU has it (Debian's x86-64 baseline is SSE2)
#endif

namespace nelf {

namespace {

// GCC/Clang vector extensions: a pixel's four channels in one register, portable C++ otherwise.
using U8x4 = std::uint8_t __attribute__((vector_size(4)));
using U8x8 = std::uint8_t __attribute__((vector_size(8)));
using U16x4 = std::uint16_t __attribute__((vector_size(8)));
using U16x8 = std::uint16_t __attribute__((vector_size(16)));
using F32x4 = float __attribute__((vector_size(16)));

constexpr int kFixedOne = 1 << 15;  // the box pass's weights are in 1/32768

#if !defined(__SSE2__)  // (render has SSE2 versions of these)
F32x4 clamp_unorm8(F32x4 value) {
  const F32x4 zero = {0.f, 0.f, 0.f, 0.f}, top = {255.f, 255.f, 255.f, 255.f};
  value = value < zero ? zero : value;
  return value > top ? top : value;
}
// GL's float → unorm8 conversion of a sum of weighted 0-255 values, alpha 255.
void store_unorm8(std::uint8_t* out, F32x4 value) {
  U8x4 bytes = __builtin_convertvector(clamp_unorm8(value) + 0.5f, U8x4);
  bytes[3] = 255;
  std::memcpy(out, &bytes, 4);
}
#endif

// A tap's four weights as 16-bit lanes: the stored bytes, the first being 256 less the others
// (256 where all four are 0, which is how a tap stores 256 on its first texel).
U16x4 tap_weights(const CompositeTable::Tap& tap) {
  const std::uint16_t rest = static_cast<std::uint16_t>(tap.weights[1] + tap.weights[2] + tap.weights[3]);
  return U16x4{static_cast<std::uint16_t>(256 - rest), tap.weights[1], tap.weights[2], tap.weights[3]};
}

// The bilinear tap at `p`: the 2×2 texels p, p + 1 texel, p + 1 row, p + 1 row + 1 texel (a row is
// `row` bytes) weighted by `weights` (out of 256, summing to 256); the four channels times 256.
// Every tap reads all four texels (clamped taps weight the repeats 0, black pixels point at a
// black texel, and the image has spare rows), so there are no branches here.
inline __attribute__((always_inline)) U16x4 bilinear(const std::uint8_t* p, std::size_t row, const U16x4 weights) {
  U8x8 upper_texels, lower_texels;
  std::memcpy(&upper_texels, p, 8);
  std::memcpy(&lower_texels, p + row, 8);
  const U16x8 upper_weights = __builtin_shufflevector(weights, weights, 0, 0, 0, 0, 1, 1, 1, 1);
  const U16x8 lower_weights = __builtin_shufflevector(weights, weights, 2, 2, 2, 2, 3, 3, 3, 3);
  // Each lane ≤ 255 · its weight, so the sum of all four stays ≤ 255 · 256.
  const U16x8 sum = __builtin_convertvector(upper_texels, U16x8) * upper_weights +
                    __builtin_convertvector(lower_texels, U16x8) * lower_weights;
  return __builtin_shufflevector(sum, sum, 0, 1, 2, 3) + __builtin_shufflevector(sum, sum, 4, 5, 6, 7);
}

#if defined(__SSE2__)
// bilinear() for two taps at once, `w` holding their weights as [a, b, a, b] (32-bit lanes): the
// channels times 256, a's in the low four 16-bit lanes, b's in the high four.
inline __attribute__((always_inline)) __m128i bilinear_pair(const std::uint8_t* pa, const std::uint8_t* pb,
                                                            std::size_t row, __m128i w) {
  const __m128i zero = _mm_setzero_si128();
  // Each weight byte ×4 (one per channel), then as 16-bit lanes: [w0 ×4, w1 ×4] and [w2 ×4, w3 ×4].
  const __m128i doubled = _mm_unpacklo_epi8(w, w);
  const __m128i wa = _mm_unpacklo_epi16(doubled, doubled), wb = _mm_unpackhi_epi16(doubled, doubled);
  const auto sum = [&](const std::uint8_t* p, __m128i weights) {
    const __m128i upper = _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)), zero);
    const __m128i lower = _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p + row)), zero);
    return std::pair{upper, _mm_add_epi16(_mm_mullo_epi16(upper, _mm_unpacklo_epi8(weights, zero)),
                                          _mm_mullo_epi16(lower, _mm_unpackhi_epi8(weights, zero)))};
  };
  const auto [upper_a, a] = sum(pa, wa);
  const auto [upper_b, b] = sum(pb, wb);
  // [a's left + right texel pairs | b's]; a tap whose weights are all 0 is its first texel × 256.
  const __m128i both = _mm_add_epi16(_mm_unpacklo_epi64(a, b), _mm_unpackhi_epi64(a, b));
  const __m128i all_zero = _mm_cmpeq_epi32(w, zero);
  const __m128i first = _mm_and_si128(_mm_unpacklo_epi64(upper_a, upper_b), _mm_unpacklo_epi32(all_zero, all_zero));
  return _mm_add_epi16(both, _mm_slli_epi16(first, 8));
}
#endif

#if defined(NELF_TABLE_AVX2)
// Two taps' texel pairs (8 bytes at a and at b) as 16-bit lanes, a's in the low 128-bit lane.
__attribute__((target("avx2"), always_inline)) inline __m256i texel_pairs_avx2(const std::uint8_t* a,
                                                                               const std::uint8_t* b) {
  return _mm256_cvtepu8_epi16(_mm_unpacklo_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(a)),
                                                 _mm_loadl_epi64(reinterpret_cast<const __m128i*>(b))));
}

// Pass 1 with AVX2, four pixels an iteration: taps 0 and 1 in the low 128-bit lane, 2 and 3 in the
// high one, each lane as bilinear_pair. Returns how many pixels it did (a multiple of 4).
__attribute__((target("avx2"))) int replay_taps_avx2(const CompositeTable::Tap* taps, int count,
                                                     const std::uint8_t* image, std::size_t row, std::uint8_t* out) {
  const __m256i zero = _mm256_setzero_si256(), round = _mm256_set1_epi16(128);
  int x = 0;
  for (; x + 4 <= count; x += 4) {
    const CompositeTable::Tap* t = taps + x;
    const __m256i four = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(t));
    const __m256i w = _mm256_shuffle_epi32(four, _MM_SHUFFLE(3, 1, 3, 1));  // [w0 w1 w0 w1 | w2 w3 w2 w3]
    const __m256i doubled = _mm256_unpacklo_epi8(w, w);
    const __m256i wa = _mm256_unpacklo_epi16(doubled, doubled), wb = _mm256_unpackhi_epi16(doubled, doubled);
    const std::uint8_t *p0 = image + 4 * static_cast<std::size_t>(t[0].texel),
                       *p1 = image + 4 * static_cast<std::size_t>(t[1].texel),
                       *p2 = image + 4 * static_cast<std::size_t>(t[2].texel),
                       *p3 = image + 4 * static_cast<std::size_t>(t[3].texel);
    const __m256i upper_a = texel_pairs_avx2(p0, p2), lower_a = texel_pairs_avx2(p0 + row, p2 + row);
    const __m256i upper_b = texel_pairs_avx2(p1, p3), lower_b = texel_pairs_avx2(p1 + row, p3 + row);
    const __m256i a = _mm256_add_epi16(_mm256_mullo_epi16(upper_a, _mm256_unpacklo_epi8(wa, zero)),
                                       _mm256_mullo_epi16(lower_a, _mm256_unpackhi_epi8(wa, zero)));
    const __m256i b = _mm256_add_epi16(_mm256_mullo_epi16(upper_b, _mm256_unpacklo_epi8(wb, zero)),
                                       _mm256_mullo_epi16(lower_b, _mm256_unpackhi_epi8(wb, zero)));
    __m256i sum = _mm256_add_epi16(_mm256_unpacklo_epi64(a, b), _mm256_unpackhi_epi64(a, b));
    const __m256i all_zero = _mm256_cmpeq_epi32(w, zero);
    const __m256i first =
        _mm256_and_si256(_mm256_unpacklo_epi64(upper_a, upper_b), _mm256_unpacklo_epi32(all_zero, all_zero));
    sum = _mm256_add_epi16(sum, _mm256_slli_epi16(first, 8));
    const __m256i pixels = _mm256_srli_epi16(_mm256_add_epi16(sum, round), 8);
    const __m256i bytes = _mm256_permute4x64_epi64(_mm256_packus_epi16(pixels, pixels), _MM_SHUFFLE(3, 1, 2, 0));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 4 * x), _mm256_castsi256_si128(bytes));
  }
  return x;
}
#endif

// The box pass's two cells and their weights in one register: 16-bit [a, b] ×4 for _mm_madd_epi16.
void push_pair(std::vector<std::int16_t>& weights, int a, int b) {
  for (int i = 0; i < 4; ++i)
    weights.push_back(static_cast<std::int16_t>(a)), weights.push_back(static_cast<std::int16_t>(b));
}
// One output sample's box weights (0-1 each) in 1/32768: rounded so that their sum is the exact sum
// rounded (largest remainders first), so that the rounding errors do not add up to a bias; each
// short of 1 by a 32768th at most (the 16-bit lanes are signed).
std::vector<int> fixed_weights(const float* weights, int count) {
  std::vector<int> fixed(static_cast<std::size_t>(count));
  std::vector<std::pair<double, int>> remainders;
  double exact_sum = 0.0;
  int sum = 0;
  for (int i = 0; i < count; ++i) {
    const double exact = std::clamp(static_cast<double>(weights[i]), 0.0, 1.0) * kFixedOne;
    fixed[i] = static_cast<int>(std::floor(exact));
    exact_sum += exact, sum += fixed[i];
    remainders.emplace_back(exact - fixed[i], i);
  }
  std::sort(remainders.begin(), remainders.end(), std::greater<>());
  for (int left = static_cast<int>(std::lround(exact_sum)) - sum, k = 0; left > 0 && k < count; --left, ++k)
    ++fixed[remainders[k].second];
  for (int& w : fixed) w = std::min(w, kFixedOne - 1);
  return fixed;
}

}  // namespace

// Pass 1 for one row of `count` pixels. The hot loop of the CPU path: four pixels an iteration
// with AVX2 where the CPU has it, two with SSE2 (GCC's generic vector code for the shuffles is ~3×
// longer), the rest with bilinear(); all three give the same bytes.
void CompositeTable::replay_taps(const Tap* taps, int count, const std::uint8_t* image, std::size_t image_row,
                                 std::uint8_t* out) {
  static_assert(sizeof(Tap) == 8, "two taps are one 16-byte load");
  int x = 0;
#if defined(NELF_TABLE_AVX2)
  if (avx2::available()) x = replay_taps_avx2(taps, count, image, image_row, out);
#endif
#if defined(__SSE2__)
  const __m128i round = _mm_set1_epi16(128);
  for (; x + 2 <= count; x += 2) {
    // [a's texel, a's weights, b's texel, b's weights] → the weights as [a, b, a, b].
    const __m128i pair = _mm_loadu_si128(reinterpret_cast<const __m128i*>(taps + x));
    const __m128i weights = _mm_shuffle_epi32(pair, _MM_SHUFFLE(3, 1, 3, 1));
    const __m128i sum = bilinear_pair(image + 4 * static_cast<std::size_t>(taps[x].texel),
                                      image + 4 * static_cast<std::size_t>(taps[x + 1].texel), image_row, weights);
    const __m128i pixels = _mm_srli_epi16(_mm_add_epi16(sum, round), 8);
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out + 4 * x), _mm_packus_epi16(pixels, pixels));
  }
#endif
  for (; x < count; ++x) {
    const U16x4 sum = bilinear(image + 4 * static_cast<std::size_t>(taps[x].texel), image_row, tap_weights(taps[x]));
    const U8x4 pixel = __builtin_convertvector((sum + 128) >> 8, U8x4);
    std::memcpy(out + 4 * x, &pixel, 4);
  }
}

BoxAxis make_box_axis(int outputs, double origin, double spacing, double box, double cell, int cells, double extent) {
  BoxAxis axis;
  axis.first.reserve(static_cast<std::size_t>(outputs));
  axis.begin.reserve(static_cast<std::size_t>(outputs) + 1);
  for (int o = 0; o < outputs; ++o) {
    // As in prefilter_box.frag: only the part of the box on the view contributes; the rest is black.
    const double centre = origin + (o + 0.5) * spacing;
    const double view_lo = std::max(centre - 0.5 * box, 0.0), view_hi = std::min(centre + 0.5 * box, extent);
    const int first = std::max(static_cast<int>(std::floor(view_lo / cell)), 0);
    const int last = std::min(static_cast<int>(std::floor(view_hi / cell)), cells - 1);
    axis.first.push_back(first);
    axis.begin.push_back(static_cast<int>(axis.weights.size()));
    for (int i = first; i <= last; ++i) {
      const double overlap = std::min((i + 1) * cell, view_hi) - std::max(i * cell, view_lo);
      axis.weights.push_back(static_cast<float>(std::max(overlap, 0.0) / box));
    }
  }
  axis.begin.push_back(static_cast<int>(axis.weights.size()));
  return axis;
}

namespace {

// One Pixel per border pixel of `r`, at its place in the panel, its four parts filled by
// fill(pixel, index of the border pixel, part).
template <class Pixel, class Fill>
std::vector<Pixel> border_pixels(const CompositeTable::Recording& r, Fill fill) {
  std::vector<Pixel> pixels;
  pixels.reserve(r.border_pixels.size());
  for (std::size_t i = 0; i < r.border_pixels.size(); ++i) {
    Pixel pixel;
    pixel.x = r.border_pixels[i] % r.panel[0];
    pixel.y = r.border_pixels[i] / r.panel[0];
    for (int k = 0; k < 4; ++k) fill(pixel, i, k);
    pixels.push_back(pixel);
  }
  return pixels;
}

}  // namespace

CompositeTable::Built CompositeTable::build(const Recording& r) {
  const std::size_t pixels = static_cast<std::size_t>(std::max(r.panel[0], 0)) * std::max(r.panel[1], 0);
  const bool borders_fit = std::all_of(r.border_pixels.begin(), r.border_pixels.end(),
                                       [&](std::int32_t p) { return p >= 0 && static_cast<std::size_t>(p) < pixels; });
  if (r.panel[0] <= 0 || r.panel[1] <= 0 || r.prefiltered[0] <= 0 || r.prefiltered[1] <= 0 ||
      r.coordinates.size() != 2 * pixels || r.border_parts.size() != r.border_pixels.size() || !borders_fit)
    throw std::invalid_argument("CompositeTable: the recording is inconsistent");
  Built b;
  b.panel = r.panel;
  b.reduced = r.reduced;
  b.prefiltered = r.prefiltered;
  b.horizontal = r.horizontal;
  b.vertical = r.vertical;
  b.taps.resize(pixels);
  for (std::size_t i = 0; i < pixels; ++i)
    b.taps[i] = make_tap(r.coordinates[2 * i], r.coordinates[2 * i + 1], r.prefiltered);
  b.borders = border_pixels<BorderPixel>(r, [&](BorderPixel& pixel, std::size_t i, int k) {
    const BorderPart& part = r.border_parts[i][k];
    pixel.weights[k] = part.weight;
    if (part.weight > 0.f) pixel.taps[k] = make_tap(part.x, part.y, r.prefiltered);
  });
  if (r.depth) {
    const Recording::DepthRecording& d = *r.depth;
    if (d.rays.size() != 4 * pixels || d.border_parts.size() != r.border_pixels.size())
      throw std::invalid_argument("CompositeTable: the depth recording is inconsistent");
    DepthTable depth;
    depth.texture_scale = d.texture_scale;
    depth.texture_offset = d.texture_offset;
    // The gain per ray as the shader forms it: crossing × u_parallax_gain, in float.
    const auto ray = [&](float u, float v, float crossing_x, float crossing_y) {
      return DepthRay{u, v, crossing_x * d.parallax_gain[0], crossing_y * d.parallax_gain[1]};
    };
    depth.rays.reserve(pixels);
    for (std::size_t i = 0; i < pixels; ++i)
      depth.rays.push_back(ray(d.rays[4 * i], d.rays[4 * i + 1], d.rays[4 * i + 2], d.rays[4 * i + 3]));
    depth.borders = border_pixels<DepthBorderPixel>(r, [&](DepthBorderPixel& pixel, std::size_t i, int k) {
      const Recording::DepthPart& part = d.border_parts[i][k];
      pixel.weights[k] = part.weight;
      if (part.weight <= 0.f) return;
      pixel.rays[k] = ray(part.u, part.v, part.crossing_x, part.crossing_y);
      pixel.hit_pixels[k] = part.hit_pixel;
    });
    b.depth = std::move(depth);
  }
  return b;
}

CompositeTable::CompositeTable(const Recording& recording) : CompositeTable(build(recording)) {}

CompositeTable::CompositeTable(Built built) : built_(std::move(built)) {
  const auto& [panel, reduced, prefiltered, horizontal, vertical, taps, borders, depth] = built_;
  // Sizes whose products (pixels, texels, bytes) cannot overflow.
  const auto size_fits = [](std::array<int, 2> size) {
    return size[0] > 0 && size[1] > 0 && size[0] <= (1 << 15) && size[1] <= (1 << 15);
  };
  const auto axis_fits = [](const BoxAxis& axis, int outputs, int cells) {
    if (axis.first.size() != static_cast<std::size_t>(outputs) || axis.begin.size() != axis.first.size() + 1 ||
        axis.begin.front() != 0 || static_cast<std::size_t>(axis.begin.back()) != axis.weights.size())
      return false;
    for (int o = 0; o < outputs; ++o)
      if (const int count = axis.begin[o + 1] - axis.begin[o];
          count < 0 || (count > 0 && (axis.first[o] < 0 || axis.first[o] > cells - count)))
        return false;
    return std::all_of(axis.weights.begin(), axis.weights.end(), [](float w) { return std::isfinite(w); });
  };
  // A tap reads the 2×2 texels from its own (8 bytes a row) and is the black texel at most: the
  // image has two spare rows and one spare texel pair. Its weights sum to 256, or are all 0.
  const std::int64_t last_texel = std::int64_t{prefiltered[0]} * (prefiltered[1] + 1);
  const auto tap_fits = [&](const Tap& tap) {
    const int sum = tap.weights[0] + tap.weights[1] + tap.weights[2] + tap.weights[3];
    return tap.texel >= 0 && tap.texel <= last_texel && (sum == 256 || sum == 0);
  };
  const auto border_fits = [&](const BorderPixel& b) {
    return b.x >= 0 && b.x < panel[0] && b.y >= 0 && b.y < panel[1] &&
           std::all_of(b.taps.begin(), b.taps.end(), tap_fits) &&
           std::all_of(b.weights.begin(), b.weights.end(), [](float w) { return std::isfinite(w); });
  };
  if (!size_fits(panel) || !size_fits(reduced) || !size_fits(prefiltered) ||
      taps.size() != static_cast<std::size_t>(panel[0]) * panel[1] ||
      !axis_fits(horizontal, prefiltered[0], reduced[0]) || !axis_fits(vertical, prefiltered[1], reduced[1]) ||
      !std::all_of(taps.begin(), taps.end(), tap_fits) || !std::all_of(borders.begin(), borders.end(), border_fits) ||
      !std::is_sorted(borders.begin(), borders.end(),
                      [](const BorderPixel& a, const BorderPixel& b) { return a.y < b.y; }))
    throw std::invalid_argument("CompositeTable: the table is inconsistent");
  if (depth) {
    // Rays and gains finite (the tap clamps any finite coordinate into the image), each border part
    // taking the crossing of a pixel of the panel.
    const auto finite = [](const DepthRay& r) {
      return std::isfinite(r.u) && std::isfinite(r.v) && std::isfinite(r.gain_u) && std::isfinite(r.gain_v);
    };
    const std::int64_t pixels = std::int64_t{panel[0]} * panel[1];
    const auto depth_border_fits = [&](const DepthBorderPixel& b) {
      for (int k = 0; k < 4; ++k)
        if (!std::isfinite(b.weights[k]) || !finite(b.rays[k]) || b.hit_pixels[k] < 0 || b.hit_pixels[k] >= pixels)
          return false;
      return b.x >= 0 && b.x < panel[0] && b.y >= 0 && b.y < panel[1];
    };
    if (depth->rays.size() != taps.size() || !std::all_of(depth->rays.begin(), depth->rays.end(), finite) ||
        !std::all_of(depth->borders.begin(), depth->borders.end(), depth_border_fits) ||
        !std::all_of(depth->texture_scale.begin(), depth->texture_scale.end(),
                     [](float v) { return std::isfinite(v); }) ||
        !std::all_of(depth->texture_offset.begin(), depth->texture_offset.end(),
                     [](float v) { return std::isfinite(v); }))
      throw std::invalid_argument("CompositeTable: the table's depth rays are inconsistent");
    hits_.assign(depth->rays.size(), 0.f);
    row_taps_.resize(static_cast<std::size_t>(panel[0]));
  }

  // The box pass in fixed point. Along x every output sample takes the same number of cell pairs
  // (zero weights pad the shorter ones; the input row has that many spare cells), and the outputs
  // are padded to a multiple of four, so the loop has no branches.
  const int out_w = prefiltered[0], out_w4 = (out_w + 3) / 4 * 4;
  horizontal_.pairs = 1;
  for (int o = 0; o < out_w; ++o)
    horizontal_.pairs = std::max(horizontal_.pairs, (horizontal.begin[o + 1] - horizontal.begin[o] + 1) / 2);
  for (int o = 0; o < out_w4; ++o) {
    const int begin = o < out_w ? horizontal.begin[o] : 0, count = o < out_w ? horizontal.begin[o + 1] - begin : 0;
    horizontal_.first.push_back(count > 0 ? horizontal.first[o] : 0);
    const std::vector<int> fixed = fixed_weights(horizontal.weights.data() + begin, count);
    const auto weight = [&](int i) { return i < count ? fixed[i] : 0; };
    for (int j = 0; j < horizontal_.pairs; ++j) push_pair(horizontal_.weights, weight(2 * j), weight(2 * j + 1));
  }
  // Along y each output row takes its own number of row pairs (a row pair's second row may be the
  // spare zero row below the last).
  vertical_.begin.push_back(0);
  for (int o = 0; o < prefiltered[1]; ++o) {
    const int begin = vertical.begin[o], count = vertical.begin[o + 1] - begin;
    vertical_.first.push_back(count > 0 ? vertical.first[o] : 0);
    const std::vector<int> fixed = fixed_weights(vertical.weights.data() + begin, count);
    const auto weight = [&](int i) { return i < count ? fixed[i] : 0; };
    for (int j = 0; j < (count + 1) / 2; ++j) push_pair(vertical_.weights, weight(2 * j), weight(2 * j + 1));
    vertical_.begin.push_back(static_cast<std::int32_t>(vertical_.weights.size() / 8));
  }

  // The input row with room for the padded pairs' cells and an 8-byte read past them.
  input_.assign((static_cast<std::size_t>(reduced[0]) + 2 * horizontal_.pairs + 2) * 4, 0);
  across_row_ = static_cast<std::size_t>(out_w4) * 4;
  across_.assign(across_row_ * (reduced[1] + 1), 0);  // one spare zero row
  // Two spare rows of opaque black and a spare texel pair: the black texel black pixels point at
  // (the first spare row's first texel), and room for a tap to read 2×2 texels (8 bytes a row).
  image_.resize(static_cast<std::size_t>(out_w) * (prefiltered[1] + 2) * 4 + 8);
  for (std::size_t i = static_cast<std::size_t>(out_w) * prefiltered[1] * 4; i < image_.size(); i += 4)
    image_[i] = image_[i + 1] = image_[i + 2] = 0, image_[i + 3] = 255;
}

CompositeTable::Tap CompositeTable::make_tap(float u, float v, std::array<int, 2> prefiltered) {
  Tap tap;
  tap.texel = prefiltered[0] * prefiltered[1];  // the black texel, all the weight on it
  if (u < 0.f || v < 0.f) return tap;           // the map's "black"
  // GL_LINEAR with GL_CLAMP_TO_EDGE: texel centres at (i + ½) / size; each of the four texels
  // clamped into the texture on its own.
  const double size[2] = {static_cast<double>(prefiltered[0]), static_cast<double>(prefiltered[1])};
  double coordinate[2] = {u * size[0] - 0.5, v * size[1] - 0.5};
  int lo[2];
  double fraction[2];
  for (int a = 0; a < 2; ++a) {
    // Held within a texel of the image (whatever the coordinate: a depth-aware tap's may be
    // anything finite, or not), where converting it to int is defined and the clamps below give
    // what they would; floor without a libm call (this runs per pixel per frame with depth).
    double& c = coordinate[a];
    c = c > -2.0 ? c : -2.0;
    c = c < size[a] + 1.0 ? c : size[a] + 1.0;
    const int truncated = static_cast<int>(c);
    const int i = truncated > c ? truncated - 1 : truncated;
    const int last = prefiltered[a] - 1;
    lo[a] = std::clamp(i, 0, last);
    // Clamped at the edge both texels are the same one: all the weight on the first.
    fraction[a] = std::clamp(i + 1, 0, last) == lo[a] ? 0.0 : coordinate[a] - i;
  }
  const int texel = lo[1] * prefiltered[0] + lo[0];
  // The four products in 8 bits, rounded so that they still sum to 256 (the largest takes the rest).
  const double exact[4] = {(1 - fraction[0]) * (1 - fraction[1]), fraction[0] * (1 - fraction[1]),
                           (1 - fraction[0]) * fraction[1], fraction[0] * fraction[1]};
  int weights[4], total = 0, largest = 0;
  for (int k = 0; k < 4; ++k) {
    weights[k] = static_cast<int>(exact[k] * 256.0 + 0.5);  // lround: exact ≥ 0
    total += weights[k];
    if (exact[k] > exact[largest]) largest = k;
  }
  weights[largest] += 256 - total;
  // All the weight on one texel is that texel's tap alone (all weights 0); only a texel with a
  // fraction > 0 towards it can have a weight, so it is in the image.
  const int offsets[4] = {0, 1, prefiltered[0], prefiltered[0] + 1};
  for (int k = 0; k < 4; ++k)
    if (weights[k] == 256) {
      tap.texel = texel + offsets[k];
      return tap;
    }
  tap.texel = texel;
  for (int k = 0; k < 4; ++k) tap.weights[k] = static_cast<std::uint8_t>(weights[k]);
  return tap;
}

namespace {

#if defined(__SSE2__)
// One output sample of the box pass along x: the sum of its cell pairs from `p` (RGBA8), `w` their
// weights, rounded to whole codes (weights in 1/32768, so the sum carries 15 fraction bits).
template <int kPairs>
inline __attribute__((always_inline)) __m128i box_sample(const std::uint8_t* p, const std::int16_t* w, int pairs) {
  const __m128i zero = _mm_setzero_si128();
  __m128i sum = _mm_set1_epi32(kFixedOne / 2);
  for (int j = 0; j < (kPairs > 0 ? kPairs : pairs); ++j, p += 8, w += 8) {
    // Cells a and b as 16-bit [a0 b0 a1 b1 a2 b2 a3 b3]: a channel's two cells side by side for madd.
    const __m128i cells = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p));
    const __m128i paired = _mm_unpacklo_epi8(_mm_unpacklo_epi8(cells, _mm_srli_si128(cells, 4)), zero);
    sum = _mm_add_epi32(sum, _mm_madd_epi16(paired, _mm_loadu_si128(reinterpret_cast<const __m128i*>(w))));
  }
  return _mm_srai_epi32(sum, 15);
}

// The box pass along x for one row: `outputs` (a multiple of 4) samples from the cells in `in`.
template <int kPairs>
void box_row_across(const std::uint8_t* in, const std::int32_t* first, const std::int16_t* weights, int pairs,
                    int outputs, std::uint8_t* out) {
  const int step = 8 * (kPairs > 0 ? kPairs : pairs);
  for (int o = 0; o < outputs; o += 4, weights += 4 * step) {
    const __m128i a = box_sample<kPairs>(in + 4 * first[o], weights, pairs);
    const __m128i b = box_sample<kPairs>(in + 4 * first[o + 1], weights + step, pairs);
    const __m128i c = box_sample<kPairs>(in + 4 * first[o + 2], weights + 2 * step, pairs);
    const __m128i d = box_sample<kPairs>(in + 4 * first[o + 3], weights + 3 * step, pairs);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 4 * o),
                     _mm_packus_epi16(_mm_packs_epi32(a, b), _mm_packs_epi32(c, d)));
  }
}

// The box pass along y for one output row of `bytes` bytes: `pairs` row pairs from `rows` (`row`
// bytes apart, readable in 16-byte steps up to a multiple of 16), alpha 255.
void box_row_down(const std::uint8_t* rows, std::size_t row, const std::int16_t* weights, int pairs, int bytes,
                  std::uint8_t* out) {
  const __m128i zero = _mm_setzero_si128(), half = _mm_set1_epi32(kFixedOne / 2);
  const __m128i alpha = _mm_set1_epi32(static_cast<int>(0xff000000u));
  const auto four_pixels = [&](int x) {
    __m128i s0 = half, s1 = half, s2 = half, s3 = half;
    for (int j = 0; j < pairs; ++j) {
      const std::uint8_t* a = rows + 2 * j * row + x;
      const __m128i upper = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a));
      const __m128i lower = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + row));
      const __m128i w = _mm_loadu_si128(reinterpret_cast<const __m128i*>(weights + 8 * j));
      // The two rows' bytes side by side, then as 16-bit lanes: a pixel's channels per madd.
      const __m128i lo = _mm_unpacklo_epi8(upper, lower), hi = _mm_unpackhi_epi8(upper, lower);
      s0 = _mm_add_epi32(s0, _mm_madd_epi16(_mm_unpacklo_epi8(lo, zero), w));
      s1 = _mm_add_epi32(s1, _mm_madd_epi16(_mm_unpackhi_epi8(lo, zero), w));
      s2 = _mm_add_epi32(s2, _mm_madd_epi16(_mm_unpacklo_epi8(hi, zero), w));
      s3 = _mm_add_epi32(s3, _mm_madd_epi16(_mm_unpackhi_epi8(hi, zero), w));
    }
    const __m128i p01 = _mm_packs_epi32(_mm_srai_epi32(s0, 15), _mm_srai_epi32(s1, 15));
    const __m128i p23 = _mm_packs_epi32(_mm_srai_epi32(s2, 15), _mm_srai_epi32(s3, 15));
    return _mm_or_si128(_mm_packus_epi16(p01, p23), alpha);
  };
  int x = 0;
  for (; x + 16 <= bytes; x += 16) _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x), four_pixels(x));
  if (x < bytes) {  // the row's last pixels: the image's rows are not padded
    const __m128i last = four_pixels(x);
    std::memcpy(out + x, &last, static_cast<std::size_t>(bytes - x));
  }
}
#else
// Portable versions of the above, with the same arithmetic (a pixel's channels as one vector).
using U32x4 = std::uint32_t __attribute__((vector_size(16)));
U32x4 cell(const std::uint8_t* p) {
  U8x4 bytes;
  std::memcpy(&bytes, p, 4);
  return __builtin_convertvector(bytes, U32x4);
}
void store_box_codes(std::uint8_t* out, U32x4 sum, bool opaque) {
  sum = (sum + static_cast<std::uint32_t>(kFixedOne / 2)) >> 15;
  U8x4 bytes = __builtin_convertvector(sum > 255u ? 255u : sum, U8x4);
  if (opaque) bytes[3] = 255;
  std::memcpy(out, &bytes, 4);
}
void box_row_across(const std::uint8_t* in, const std::int32_t* first, const std::int16_t* weights, int pairs,
                    int outputs, std::uint8_t* out) {
  for (int o = 0; o < outputs; ++o) {
    U32x4 sum = {0, 0, 0, 0};
    for (int j = 0; j < pairs; ++j) {
      const std::uint8_t* p = in + 4 * (first[o] + 2 * j);
      const std::int16_t* w = weights + (static_cast<std::size_t>(o) * pairs + j) * 8;
      sum += cell(p) * static_cast<std::uint32_t>(w[0]) + cell(p + 4) * static_cast<std::uint32_t>(w[1]);
    }
    store_box_codes(out + 4 * o, sum, false);
  }
}
void box_row_down(const std::uint8_t* rows, std::size_t row, const std::int16_t* weights, int pairs, int bytes,
                  std::uint8_t* out) {
  for (int x = 0; x < bytes; x += 4) {
    U32x4 sum = {0, 0, 0, 0};
    for (int j = 0; j < pairs; ++j)
      sum += cell(rows + 2 * j * row + x) * static_cast<std::uint32_t>(weights[8 * j]) +
             cell(rows + (2 * j + 1) * row + x) * static_cast<std::uint32_t>(weights[8 * j + 1]);
    store_box_codes(out + x, sum, true);
  }
}
#endif

// Pass 2 for one border pixel: each part of the aperture through its lens (its tap), weighted by
// its area, in float, into `out`.
void border_pixel(const CompositeTable::BorderPixel& b, const std::uint8_t* image, std::size_t image_row,
                  std::uint8_t* out) {
#if defined(__SSE2__)
  // The same arithmetic as below, branch-free: a part without weight adds 0 × its (finite) tap.
  const __m128i zero = _mm_setzero_si128();
  const auto pair_weights = [](const CompositeTable::Tap* taps) {  // [a, b, a, b], as in replay_taps
    return _mm_shuffle_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(taps)), _MM_SHUFFLE(3, 1, 3, 1));
  };
  const auto at = [&](int k) { return image + 4 * static_cast<std::size_t>(b.taps[k].texel); };
  const __m128i sum01 = bilinear_pair(at(0), at(1), image_row, pair_weights(&b.taps[0]));
  const __m128i sum23 = bilinear_pair(at(2), at(3), image_row, pair_weights(&b.taps[2]));
  const __m128 parts = _mm_loadu_ps(b.weights.data());
  // weight / 256 is exact, so × (1/256) is the same.
  const __m128 w = _mm_mul_ps(_mm_and_ps(_mm_cmpgt_ps(parts, _mm_setzero_ps()), parts), _mm_set1_ps(1.f / 256.f));
  __m128 sum = _mm_mul_ps(_mm_shuffle_ps(w, w, 0x00), _mm_cvtepi32_ps(_mm_unpacklo_epi16(sum01, zero)));
  sum = _mm_add_ps(sum, _mm_mul_ps(_mm_shuffle_ps(w, w, 0x55), _mm_cvtepi32_ps(_mm_unpackhi_epi16(sum01, zero))));
  sum = _mm_add_ps(sum, _mm_mul_ps(_mm_shuffle_ps(w, w, 0xaa), _mm_cvtepi32_ps(_mm_unpacklo_epi16(sum23, zero))));
  sum = _mm_add_ps(sum, _mm_mul_ps(_mm_shuffle_ps(w, w, 0xff), _mm_cvtepi32_ps(_mm_unpackhi_epi16(sum23, zero))));
  // store_unorm8: clamped, + ½, truncated; alpha 255.
  sum = _mm_min_ps(_mm_max_ps(sum, _mm_setzero_ps()), _mm_set1_ps(255.f));
  const __m128i codes = _mm_cvttps_epi32(_mm_add_ps(sum, _mm_set1_ps(0.5f)));
  const __m128i bytes = _mm_packus_epi16(_mm_packs_epi32(codes, codes), zero);
  const std::uint32_t pixel = static_cast<std::uint32_t>(_mm_cvtsi128_si32(bytes)) | 0xff000000u;
  std::memcpy(out, &pixel, 4);
#else
  F32x4 sum = {0.f, 0.f, 0.f, 0.f};
  for (int k = 0; k < 4; ++k) {
    if (b.weights[k] <= 0.f) continue;
    const U16x4 v = bilinear(image + 4 * static_cast<std::size_t>(b.taps[k].texel), image_row, tap_weights(b.taps[k]));
    sum += (b.weights[k] / 256.f) * __builtin_convertvector(v, F32x4);
  }
  store_unorm8(out, sum);
#endif
}

// A row of `pixels` block means into `out`: as they are, or with red and blue exchanged (every pass
// after the first copy is the same for each colour channel, so the eye comes out in that order).
void copy_means_row(const std::uint8_t* in, std::uint8_t* out, std::size_t pixels, ChannelOrder order) {
  if (order == ChannelOrder::rgba) {
    std::memcpy(out, in, pixels * 4);
    return;
  }
  std::size_t i = 0;
#if defined(__SSE2__)
  // Little-endian pixels as 32-bit lanes 0xAABBGGRR: keep A and G, move R up and B down.
  const __m128i green_alpha = _mm_set1_epi32(static_cast<int>(0xFF00FF00u)), low = _mm_set1_epi32(0xFF);
  for (; i + 4 <= pixels; i += 4) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + 4 * i));
    const __m128i swapped = _mm_or_si128(
        _mm_and_si128(v, green_alpha),
        _mm_or_si128(_mm_and_si128(_mm_srli_epi32(v, 16), low), _mm_slli_epi32(_mm_and_si128(v, low), 16)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 4 * i), swapped);
  }
#endif
  for (; i < pixels; ++i) {
    out[4 * i] = in[4 * i + 2];
    out[4 * i + 1] = in[4 * i + 1];
    out[4 * i + 2] = in[4 * i];
    out[4 * i + 3] = in[4 * i + 3];
  }
}

}  // namespace

// The prefilter's box pass in fixed point: weights in 1/32768 (fixed_weights: each within a
// 32768th of its float, a sample's sum its float sum rounded), 8-bit cells times 16-bit weights
// summed exactly in 32 bits (_mm_madd_epi16), each pass rounded to whole codes (half up), as GL's
// RGBA8 intermediate and target hold them. It was float: the only difference is the weights'
// rounding, which moves a code by one where the exact sum is within ~0.01 of a half (~0.02 % of
// the eye's values on test charts; against GL the mean difference stays 0.043 codes).
void CompositeTable::box_pass(const std::uint8_t* reduced, std::size_t reduced_stride, ChannelOrder order) {
  const std::array<int, 2> size = built_.reduced, prefiltered = built_.prefiltered;
  // Along x: a row of block means at a time (copied into input_, whose spare cells the padded pairs
  // may read) → across_ (padded prefiltered width, reduced height).
  const int outputs = static_cast<int>(across_row_ / 4), pairs = horizontal_.pairs;
  for (int y = 0; y < size[1]; ++y) {
    copy_means_row(reduced + static_cast<std::size_t>(y) * reduced_stride, input_.data(),
                   static_cast<std::size_t>(size[0]), order);
    std::uint8_t* out = &across_[static_cast<std::size_t>(y) * across_row_];
    const std::int32_t* first = horizontal_.first.data();
    const std::int16_t* weights = horizontal_.weights.data();
#if defined(__SSE2__)
    switch (pairs) {  // the usual counts unrolled
      case 1:
        box_row_across<1>(input_.data(), first, weights, pairs, outputs, out);
        break;
      case 2:
        box_row_across<2>(input_.data(), first, weights, pairs, outputs, out);
        break;
      case 3:
        box_row_across<3>(input_.data(), first, weights, pairs, outputs, out);
        break;
      default:
        box_row_across<0>(input_.data(), first, weights, pairs, outputs, out);
        break;
    }
#else
    box_row_across(input_.data(), first, weights, pairs, outputs, out);
#endif
  }
  // Along y: across_ → image_, a row at a time.
  const int bytes = prefiltered[0] * 4;
  for (int y = 0; y < prefiltered[1]; ++y)
    box_row_down(&across_[static_cast<std::size_t>(vertical_.first[y]) * across_row_], across_row_,
                 &vertical_.weights[static_cast<std::size_t>(vertical_.begin[y]) * 8],
                 vertical_.begin[y + 1] - vertical_.begin[y], bytes, &image_[static_cast<std::size_t>(y) * bytes]);
}

void CompositeTable::render(const std::uint8_t* reduced, std::size_t reduced_stride, std::uint8_t* out,
                            std::size_t out_stride, ChannelOrder order, const DisparitySurface* surface) {
  if (surface && !built_.depth)
    throw std::logic_error("CompositeTable::render: a surface given to a table recorded without depth");
  box_pass(reduced, reduced_stride, order);
  if (surface) {
    render_depth(*surface, out, out_stride);
    return;
  }

  // Pass 1, one bilinear tap per pixel, a row at a time; then pass 2 for the row's pixels along the
  // elemental-image borders (sorted by row) while the row is still in the cache.
  const std::uint8_t* image = image_.data();
  const std::size_t image_row = static_cast<std::size_t>(built_.prefiltered[0]) * 4;
  const int width = built_.panel[0];
  auto border = built_.borders.begin();
  for (int y = 0; y < built_.panel[1]; ++y) {
    std::uint8_t* row = out + static_cast<std::size_t>(y) * out_stride;
    replay_taps(&built_.taps[static_cast<std::size_t>(y) * width], width, image, image_row, row);
    for (; border != built_.borders.end() && border->y == y; ++border)
      border_pixel(*border, image, image_row, row + 4 * static_cast<std::size_t>(border->x));
  }
}

// The depth-aware composite (shaders/elemental_depth_lookup.frag, then the border strips of
// elemental.frag with NELF_DEPTH_HITS): per pixel the search for where its ray meets the surface and
// one tap there (depth_taps.hpp), replayed a row at a time with the flat table's arithmetic; then
// the border pixels, each part through its lens where its ray meets the surface at the crossing its
// hit pixel found. Pass 1 goes first over all rows: a part may take a crossing from the row below.
void CompositeTable::render_depth(const DisparitySurface& surface, std::uint8_t* out, std::size_t out_stride) {
  const DepthTable& depth = *built_.depth;
  const std::uint8_t* image = image_.data();
  const std::size_t image_row = static_cast<std::size_t>(built_.prefiltered[0]) * 4;
  const int width = built_.panel[0];
  const DepthTapImage taps_read{built_.prefiltered, depth.texture_scale, depth.texture_offset};
  const Tap black = make_tap(-1.f, -1.f, built_.prefiltered);
  static_assert(sizeof(DepthRay) == 4 * sizeof(float), "a row of rays is four floats a ray");
  for (int y = 0; y < built_.panel[1]; ++y) {
    const std::size_t first = static_cast<std::size_t>(y) * width;
    // The row's searches at once (black pixels too, without a branch: their taps are the black
    // texel, and their crossings, as GL's, are kept for the strips).
    surface.crossings(&depth.rays[first].u, width, &hits_[first]);
    depth_taps(&depth.rays[first], &hits_[first], width, taps_read, black, row_taps_.data());
    replay_taps(row_taps_.data(), width, image, image_row, out + static_cast<std::size_t>(y) * out_stride);
  }
  for (const DepthBorderPixel& b : depth.borders) {
    BorderPixel pixel;
    pixel.weights = b.weights;
    for (int k = 0; k < 4; ++k)
      if (b.weights[k] > 0.f)
        pixel.taps[k] = depth_tap(b.rays[k], hits_[static_cast<std::size_t>(b.hit_pixels[k])], taps_read);
    border_pixel(pixel, image, image_row,
                 out + static_cast<std::size_t>(b.y) * out_stride + 4 * static_cast<std::size_t>(b.x));
  }
}

void fill_opaque_black(std::span<std::uint8_t> rgba) {
  const std::uint8_t black[4] = {0, 0, 0, 255};
  for (std::size_t i = 0; i + 4 <= rgba.size(); i += 4) std::memcpy(&rgba[i], black, 4);
}

void render_packed_eyes(std::array<std::optional<CompositeTable>, 2>& tables,
                        const std::array<const std::uint8_t*, 2>& views, std::size_t view_stride,
                        const std::array<std::optional<std::pair<int, int>>, 2>& origins, std::uint8_t* packed,
                        std::size_t stride, ChannelOrder order,
                        const std::array<const DisparitySurface*, 2>& surfaces) {
  const auto render_eye = [&](int e) {
    if (!origins[e] || !tables[e]) return;
    tables[e]->render(views[e], view_stride,
                      packed + static_cast<std::size_t>(origins[e]->second) * stride +
                          static_cast<std::size_t>(origins[e]->first) * 4,
                      stride, order, surfaces[e]);
  };
  auto right = std::async(std::launch::async, render_eye, 1);
  render_eye(0);
  right.get();
}

}  // namespace nelf
