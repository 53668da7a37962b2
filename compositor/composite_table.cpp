#include "compositor/composite_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <future>
#include <stdexcept>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace nelf {

namespace {

// GCC/Clang vector extensions: a pixel's four channels in one register, portable C++ otherwise.
using U8x4 = std::uint8_t __attribute__((vector_size(4)));
using U8x8 = std::uint8_t __attribute__((vector_size(8)));
using U8x16 = std::uint8_t __attribute__((vector_size(16)));
using U16x4 = std::uint16_t __attribute__((vector_size(8)));
using U16x8 = std::uint16_t __attribute__((vector_size(16)));
using F32x4 = float __attribute__((vector_size(16)));
using I32x4 = std::int32_t __attribute__((vector_size(16)));

F32x4 load_float4(const float* p) {
  F32x4 v;
  std::memcpy(&v, p, 16);
  return v;
}
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

}  // namespace

// Pass 1 for one row of `count` pixels. The hot loop of the CPU path: with SSE2 two pixels per
// iteration (GCC's generic vector code for the shuffles is ~3× longer), else bilinear().
void CompositeTable::replay_taps(const Tap* taps, int count, const std::uint8_t* image, std::size_t image_row,
                                 std::uint8_t* out) {
  int x = 0;
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128(), round = _mm_set1_epi16(128);
  const auto tap_sum = [&](const Tap& tap) {
    const __m128i w = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(tap.weights));
    const __m128i upper_weights = _mm_unpacklo_epi64(_mm_shufflelo_epi16(w, 0x00), _mm_shufflelo_epi16(w, 0x55));
    const __m128i lower_weights = _mm_unpacklo_epi64(_mm_shufflelo_epi16(w, 0xaa), _mm_shufflelo_epi16(w, 0xff));
    const std::uint8_t* p = image + 4 * static_cast<std::size_t>(tap.texel);
    const __m128i upper = _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)), zero);
    const __m128i lower = _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p + image_row)), zero);
    return _mm_add_epi16(_mm_mullo_epi16(upper, upper_weights), _mm_mullo_epi16(lower, lower_weights));
  };
  for (; x + 2 <= count; x += 2) {
    const __m128i a = tap_sum(taps[x]), b = tap_sum(taps[x + 1]);
    // [a's left + right texel pairs | b's], rounded, to bytes.
    const __m128i both = _mm_add_epi16(_mm_unpacklo_epi64(a, b), _mm_unpackhi_epi64(a, b));
    const __m128i pixels = _mm_srli_epi16(_mm_add_epi16(both, round), 8);
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out + 4 * x), _mm_packus_epi16(pixels, pixels));
  }
#endif
  for (; x < count; ++x) {
    U16x4 weights;
    std::memcpy(&weights, taps[x].weights, 8);
    const U16x4 sum = bilinear(image + 4 * static_cast<std::size_t>(taps[x].texel), image_row, weights);
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

CompositeTable::CompositeTable(const Recording& r)
    : panel_(r.panel),
      reduced_(r.reduced),
      prefiltered_(r.prefiltered),
      horizontal_(r.horizontal),
      vertical_(r.vertical) {
  const std::size_t pixels = static_cast<std::size_t>(panel_[0]) * panel_[1];
  // A recording may come from a cache file: everything that indexes memory is checked.
  const auto axis_fits = [](const BoxAxis& axis, int outputs, int cells) {
    if (axis.first.size() != static_cast<std::size_t>(outputs) || axis.begin.size() != axis.first.size() + 1 ||
        axis.begin.front() != 0 || static_cast<std::size_t>(axis.begin.back()) != axis.weights.size())
      return false;
    for (int o = 0; o < outputs; ++o)
      if (const int count = axis.begin[o + 1] - axis.begin[o];
          count < 0 || (count > 0 && (axis.first[o] < 0 || axis.first[o] + count > cells)))
        return false;
    return true;
  };
  const bool borders_fit = std::all_of(r.border_pixels.begin(), r.border_pixels.end(),
                                       [&](std::int32_t p) { return p >= 0 && static_cast<std::size_t>(p) < pixels; });
  if (panel_[0] <= 0 || panel_[1] <= 0 || reduced_[0] <= 0 || reduced_[1] <= 0 || prefiltered_[0] <= 0 ||
      prefiltered_[1] <= 0 || r.coordinates.size() != 2 * pixels || r.border_parts.size() != r.border_pixels.size() ||
      !borders_fit || !axis_fits(horizontal_, prefiltered_[0], reduced_[0]) ||
      !axis_fits(vertical_, prefiltered_[1], reduced_[1]))
    throw std::invalid_argument("CompositeTable: the recording is inconsistent");
  taps_.resize(pixels);
  for (std::size_t i = 0; i < pixels; ++i) taps_[i] = make_tap(r.coordinates[2 * i], r.coordinates[2 * i + 1]);
  borders_.reserve(r.border_pixels.size());
  for (std::size_t i = 0; i < r.border_pixels.size(); ++i) {
    BorderPixel b;
    b.pixel = r.border_pixels[i];
    for (int k = 0; k < 4; ++k) {
      const BorderPart& part = r.border_parts[i][k];
      b.weights[k] = part.weight;
      if (part.weight > 0.f) b.taps[k] = make_tap(part.x, part.y);
    }
    borders_.push_back(b);
  }
  input_.resize(static_cast<std::size_t>(reduced_[0]) * 4);
  across_.resize(static_cast<std::size_t>(prefiltered_[0]) * reduced_[1] * 4);
  // Two spare rows of opaque black: the black texel black pixels point at (the first spare row's
  // first texel), and room for bilinear() to read 2×2 texels from any tap.
  image_.resize(static_cast<std::size_t>(prefiltered_[0]) * (prefiltered_[1] + 2) * 4);
  for (std::size_t i = static_cast<std::size_t>(prefiltered_[0]) * prefiltered_[1] * 4; i < image_.size(); i += 4)
    image_[i] = image_[i + 1] = image_[i + 2] = 0, image_[i + 3] = 255;
}

CompositeTable::Tap CompositeTable::make_tap(float u, float v) const {
  Tap tap;
  tap.texel = prefiltered_[0] * prefiltered_[1];  // the black texel
  tap.weights[0] = 256;
  if (u < 0.f || v < 0.f) return tap;  // the map's "black": the black texel
  // GL_LINEAR with GL_CLAMP_TO_EDGE: texel centres at (i + ½) / size; each of the four texels
  // clamped into the texture on its own.
  const double size[2] = {static_cast<double>(prefiltered_[0]), static_cast<double>(prefiltered_[1])};
  const double coordinate[2] = {u * size[0] - 0.5, v * size[1] - 0.5};
  int lo[2];
  double fraction[2];
  for (int a = 0; a < 2; ++a) {
    const int i = static_cast<int>(std::floor(coordinate[a]));
    const int last = prefiltered_[a] - 1;
    lo[a] = std::clamp(i, 0, last);
    // Clamped at the edge both texels are the same one: all the weight on the first.
    fraction[a] = std::clamp(i + 1, 0, last) == lo[a] ? 0.0 : coordinate[a] - i;
  }
  tap.texel = lo[1] * prefiltered_[0] + lo[0];
  // The four products in 8 bits, rounded so that they still sum to 256 (the largest takes the rest).
  const double exact[4] = {(1 - fraction[0]) * (1 - fraction[1]), fraction[0] * (1 - fraction[1]),
                           (1 - fraction[0]) * fraction[1], fraction[0] * fraction[1]};
  int total = 0, largest = 0;
  for (int k = 0; k < 4; ++k) {
    tap.weights[k] = static_cast<std::uint16_t>(std::lround(exact[k] * 256.0));
    total += tap.weights[k];
    if (exact[k] > exact[largest]) largest = k;
  }
  tap.weights[largest] = static_cast<std::uint16_t>(tap.weights[largest] + 256 - total);
  return tap;
}

void CompositeTable::box_pass(const std::uint8_t* reduced, std::size_t reduced_stride) {
  // Along x: the block means, a row at a time as float (input_) → across_ (prefiltered width,
  // reduced height), rounded to whole codes as GL's RGBA8 intermediate holds them.
  const int in_w = reduced_[0], rows = reduced_[1], out_w = prefiltered_[0], out_h = prefiltered_[1];
  float* row = input_.data();
  for (int y = 0; y < rows; ++y) {
    const std::uint8_t* bytes = reduced + static_cast<std::size_t>(y) * reduced_stride;
    int i = 0;
    for (; i + 16 <= 4 * in_w; i += 16) {  // 16 bytes at a time (GCC's vectoriser leaves this loop scalar)
      U8x16 b;
      std::memcpy(&b, bytes + i, 16);
      const F32x4 f[4] = {__builtin_convertvector(__builtin_shufflevector(b, b, 0, 1, 2, 3), F32x4),
                          __builtin_convertvector(__builtin_shufflevector(b, b, 4, 5, 6, 7), F32x4),
                          __builtin_convertvector(__builtin_shufflevector(b, b, 8, 9, 10, 11), F32x4),
                          __builtin_convertvector(__builtin_shufflevector(b, b, 12, 13, 14, 15), F32x4)};
      std::memcpy(row + i, f, sizeof f);
    }
    for (; i < 4 * in_w; ++i) row[i] = bytes[i];
    float* out = &across_[static_cast<std::size_t>(y) * out_w * 4];
    for (int x = 0; x < out_w; ++x) {
      F32x4 sum = {0.f, 0.f, 0.f, 0.f};
      const float* cell = row + 4 * horizontal_.first[x];
      for (int k = horizontal_.begin[x]; k < horizontal_.begin[x + 1]; ++k, cell += 4)
        sum += horizontal_.weights[k] * load_float4(cell);
      const F32x4 rounded = __builtin_convertvector(__builtin_convertvector(clamp_unorm8(sum) + 0.5f, I32x4), F32x4);
      std::memcpy(out + 4 * x, &rounded, 16);
    }
  }
  // Along y: across_ → image_, a row at a time (the weights are per output row).
  row_sums_.resize(static_cast<std::size_t>(out_w) * 4);
  for (int y = 0; y < out_h; ++y) {
    std::fill(row_sums_.begin(), row_sums_.end(), 0.f);
    float* sum = row_sums_.data();
    for (int k = vertical_.begin[y], i = vertical_.first[y]; k < vertical_.begin[y + 1]; ++k, ++i) {
      const F32x4 w = {vertical_.weights[k], vertical_.weights[k], vertical_.weights[k], vertical_.weights[k]};
      const float* in = &across_[static_cast<std::size_t>(i) * out_w * 4];
      for (int x = 0; x < 4 * out_w; x += 4) {
        const F32x4 v = load_float4(sum + x) + w * load_float4(in + x);
        std::memcpy(sum + x, &v, 16);
      }
    }
    std::uint8_t* out = &image_[static_cast<std::size_t>(y) * out_w * 4];
    for (int x = 0; x < out_w; ++x) store_unorm8(out + 4 * x, load_float4(sum + 4 * x));
  }
}

void CompositeTable::render(const std::uint8_t* reduced, std::size_t reduced_stride, std::uint8_t* out,
                            std::size_t out_stride) {
  box_pass(reduced, reduced_stride);

  // Pass 1: one bilinear tap per pixel.
  const std::uint8_t* image = image_.data();
  const std::size_t image_row = static_cast<std::size_t>(prefiltered_[0]) * 4;
  const int width = panel_[0];
  for (int y = 0; y < panel_[1]; ++y)
    replay_taps(&taps_[static_cast<std::size_t>(y) * width], width, image, image_row,
                out + static_cast<std::size_t>(y) * out_stride);

  // Pass 2: the pixels along the elemental-image borders, each part of the aperture through its lens.
  for (const BorderPixel& b : borders_) {
    F32x4 sum = {0.f, 0.f, 0.f, 0.f};
    for (int k = 0; k < 4; ++k) {
      if (b.weights[k] <= 0.f) continue;
      U16x4 weights;
      std::memcpy(&weights, b.taps[k].weights, 8);
      const U16x4 v = bilinear(image + 4 * static_cast<std::size_t>(b.taps[k].texel), image_row, weights);
      sum += (b.weights[k] / 256.f) * __builtin_convertvector(v, F32x4);
    }
    store_unorm8(out + static_cast<std::size_t>(b.pixel / width) * out_stride + 4 * (b.pixel % width), sum);
  }
}

void render_packed_eyes(std::array<std::optional<CompositeTable>, 2>& tables,
                        const std::array<const std::uint8_t*, 2>& views, std::size_t view_stride,
                        const std::array<std::optional<std::pair<int, int>>, 2>& origins, std::uint8_t* packed,
                        std::size_t stride) {
  const auto render_eye = [&](int e) {
    if (!origins[e] || !tables[e]) return;
    tables[e]->render(views[e], view_stride,
                      packed + static_cast<std::size_t>(origins[e]->second) * stride +
                          static_cast<std::size_t>(origins[e]->first) * 4,
                      stride);
  };
  auto right = std::async(std::launch::async, render_eye, 1);
  render_eye(0);
  right.get();
}

}  // namespace nelf
