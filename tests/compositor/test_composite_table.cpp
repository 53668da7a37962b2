// CompositeTable's replay on the CPU against a plain double-precision reference of what it replays
// (no GL here: tests/compositor/gl/test_composite_table.cpp compares it with the GL path itself). The panel is
// 39 pixels wide so that every loop of pass 1 runs: four pixels at a time (AVX2), two (SSE2), one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "compositor/cpu/composite_table.hpp"

namespace nelf {
namespace {

using Bytes = std::vector<std::uint8_t>;

CompositeTable::Recording test_recording() {
  CompositeTable::Recording r;
  r.panel = {39, 9};
  r.reduced = {20, 12};
  r.prefiltered = {17, 10};
  // A 40×48 view in 2×4 cells, prefiltered with boxes 4-5 cells wide that overhang its edges.
  r.horizontal = make_box_axis(17, -1.25, 2.5, 7.7, 2.0, 20, 40.0);
  r.vertical = make_box_axis(10, -1.0, 5.0, 13.3, 4.0, 12, 48.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uniform(-0.05f, 1.05f);
  const int pixels = r.panel[0] * r.panel[1];
  for (int i = 0; i < pixels; ++i) {
    float u = uniform(rng), v = uniform(rng);
    if (i % 7 == 0) u = (static_cast<float>(i % 17) + 0.5f) / 17.f, v = (static_cast<float>(i % 10) + 0.5f) / 10.f;
    if (i % 13 == 0) v = (static_cast<float>(i % 9) + 1.499f) / 10.f;  // a thousandth above a texel's centre
    if (i % 11 == 0) u = -1.f;                                         // black
    r.coordinates.push_back(u), r.coordinates.push_back(v);
  }
  for (int p : {0, 5, 38, 40, 77, 200, 350}) {
    r.border_pixels.push_back(p);
    std::array<CompositeTable::BorderPart, 4> parts{};
    for (int k = 0; k < 4; ++k)
      if ((p + k) % 3 != 0) parts[k] = {uniform(rng), uniform(rng), 0.25f + 0.1f * static_cast<float>(k)};
    r.border_parts.push_back(parts);
  }
  return r;
}

// The box pass as prefilter_box.frag does it, in double, rounded to codes after each axis.
std::vector<double> box_reference(const CompositeTable::Recording& r, const Bytes& means) {
  const int in_w = r.reduced[0], in_h = r.reduced[1], out_w = r.prefiltered[0], out_h = r.prefiltered[1];
  const auto code = [](double v) { return std::floor(std::clamp(v, 0.0, 255.0) + 0.5); };
  std::vector<double> across(static_cast<std::size_t>(out_w) * in_h * 4),
      image(static_cast<std::size_t>(out_w) * out_h * 4);
  for (int y = 0; y < in_h; ++y)
    for (int x = 0; x < out_w; ++x)
      for (int c = 0; c < 4; ++c) {
        double sum = 0.0;
        for (int k = r.horizontal.begin[x]; k < r.horizontal.begin[x + 1]; ++k)
          sum +=
              r.horizontal.weights[k] *
              means[(static_cast<std::size_t>(y) * in_w + r.horizontal.first[x] + k - r.horizontal.begin[x]) * 4 + c];
        across[(static_cast<std::size_t>(y) * out_w + x) * 4 + c] = code(sum);
      }
  for (int y = 0; y < out_h; ++y)
    for (int x = 0; x < out_w; ++x)
      for (int c = 0; c < 4; ++c) {
        double sum = 0.0;
        for (int k = r.vertical.begin[y]; k < r.vertical.begin[y + 1]; ++k)
          sum += r.vertical.weights[k] *
                 across[(static_cast<std::size_t>(r.vertical.first[y] + k - r.vertical.begin[y]) * out_w + x) * 4 + c];
        image[(static_cast<std::size_t>(y) * out_w + x) * 4 + c] = c == 3 ? 255.0 : code(sum);
      }
  return image;
}

// GL_LINEAR with GL_CLAMP_TO_EDGE and 8-bit weights (rounded to sum to 256), times 256.
std::array<double, 4> tap_reference(const CompositeTable::Recording& r, const std::vector<double>& image, float u,
                                    float v) {
  if (u < 0.f || v < 0.f) return {0.0, 0.0, 0.0, 255.0 * 256};
  const int w = r.prefiltered[0], h = r.prefiltered[1];
  const double x = u * w - 0.5, y = v * h - 0.5;
  const int i = static_cast<int>(std::floor(x)), j = static_cast<int>(std::floor(y));
  const double fx = x - i, fy = y - j;
  const double exact[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
  const int xs[4] = {i, i + 1, i, i + 1}, ys[4] = {j, j, j + 1, j + 1};
  int weights[4], total = 0, largest = 0;
  for (int k = 0; k < 4; ++k) {
    weights[k] = static_cast<int>(std::lround(exact[k] * 256.0));
    total += weights[k];
    if (exact[k] > exact[largest]) largest = k;
  }
  weights[largest] += 256 - total;
  std::array<double, 4> sum{};
  for (int k = 0; k < 4; ++k) {
    const int tx = std::clamp(xs[k], 0, w - 1), ty = std::clamp(ys[k], 0, h - 1);
    for (int c = 0; c < 4; ++c) sum[c] += weights[k] * image[(static_cast<std::size_t>(ty) * w + tx) * 4 + c];
  }
  return sum;
}

TEST(CompositeTable, ReplaysItsRecordingLikeADoublePrecisionReference) {
  const CompositeTable::Recording r = test_recording();
  CompositeTable table(r);
  Bytes means(static_cast<std::size_t>(r.reduced[0]) * r.reduced[1] * 4);
  std::mt19937 rng(3);
  for (std::size_t i = 0; i < means.size(); ++i) means[i] = i % 4 == 3 ? 255 : static_cast<std::uint8_t>(rng());
  // Strides with padding, as in a packed frame; the padding must stay as it is.
  const std::size_t in_stride = static_cast<std::size_t>(r.reduced[0]) * 4 + 8;
  Bytes padded(in_stride * r.reduced[1], 9);
  for (int y = 0; y < r.reduced[1]; ++y)
    std::copy_n(&means[static_cast<std::size_t>(y) * r.reduced[0] * 4], r.reduced[0] * 4,
                &padded[static_cast<std::size_t>(y) * in_stride]);
  const std::size_t out_stride = static_cast<std::size_t>(r.panel[0]) * 4 + 12;
  Bytes out(out_stride * r.panel[1], 77);
  table.render(padded.data(), in_stride, out.data(), out_stride);

  const std::vector<double> image = box_reference(r, means);
  std::vector<double> expected(static_cast<std::size_t>(r.panel[0]) * r.panel[1] * 4);
  for (std::size_t p = 0; p < expected.size() / 4; ++p) {
    const auto sum = tap_reference(r, image, r.coordinates[2 * p], r.coordinates[2 * p + 1]);
    for (int c = 0; c < 4; ++c) expected[4 * p + c] = std::floor((sum[c] + 128.0) / 256.0);
  }
  for (std::size_t b = 0; b < r.border_pixels.size(); ++b) {
    std::array<double, 4> sum{};
    for (const auto& part : r.border_parts[b])
      if (part.weight > 0.f) {
        const auto tap = tap_reference(r, image, part.x, part.y);
        for (int c = 0; c < 4; ++c) sum[c] += part.weight / 256.0 * tap[c];
      }
    for (int c = 0; c < 4; ++c)
      expected[4 * static_cast<std::size_t>(r.border_pixels[b]) + c] =
          c == 3 ? 255.0 : std::floor(std::clamp(sum[c], 0.0, 255.0) + 0.5);
  }

  // The box pass is fixed point (weights in 1/32768): a code where the exact sum is within a
  // hair of a half may round the other way, so a value may be one off, rarely.
  int differ = 0;
  for (int y = 0; y < r.panel[1]; ++y) {
    for (int x = 0; x < r.panel[0]; ++x)
      for (int c = 0; c < 4; ++c) {
        const double want = expected[(static_cast<std::size_t>(y) * r.panel[0] + x) * 4 + c];
        const int got = out[y * out_stride + static_cast<std::size_t>(x) * 4 + c];
        EXPECT_LE(std::abs(got - want), 1.0) << "pixel " << x << ", " << y << " channel " << c;
        differ += got != want;
        if (c == 3) {
          EXPECT_EQ(got, 255);
        }
      }
    for (std::size_t i = static_cast<std::size_t>(r.panel[0]) * 4; i < out_stride; ++i)
      EXPECT_EQ(out[y * out_stride + i], 77);
  }
  EXPECT_LE(differ, static_cast<int>(expected.size() / 100));
  // Black pixels are black.
  for (int p = 0; p < r.panel[0] * r.panel[1]; p += 11) {
    if (std::find(r.border_pixels.begin(), r.border_pixels.end(), p) != r.border_pixels.end()) continue;
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(out[(p / r.panel[0]) * out_stride + static_cast<std::size_t>(p % r.panel[0]) * 4 + c], 0);
    }
  }
}

// A tap with all its weight on one texel (at a texel's centre, or a 256th from it) is that texel.
TEST(CompositeTable, TapsAtTexelCentresAreThoseTexels) {
  CompositeTable::Recording r;
  r.panel = {4, 1};
  r.reduced = {2, 2};
  r.prefiltered = {2, 2};
  r.horizontal = make_box_axis(2, 0.0, 1.0, 1.0, 1.0, 2, 2.0);  // one cell per sample: the means themselves
  r.vertical = make_box_axis(2, 0.0, 1.0, 1.0, 1.0, 2, 2.0);
  // Two taps at texels' centres, one halfway between two texels, one a thousandth of a texel above
  // the lower texel's centre (which the 8-bit weights round to all of the weight on that texel).
  r.coordinates = {0.25f, 0.25f, 0.75f, 0.75f, 0.25f + 0.499f / 2, 0.75f, 0.25f, 0.25f + 0.999f / 2};
  CompositeTable table(r);
  const Bytes means = {10, 20, 30, 255, 40, 50, 60, 255, 70, 80, 90, 255, 100, 110, 120, 255};
  Bytes out(16, 0);
  table.render(means.data(), 8, out.data(), 16);
  const Bytes expected = {10, 20, 30, 255, 100, 110, 120, 255, 85, 95, 105, 255, 70, 80, 90, 255};
  EXPECT_EQ(out, expected);
  // The all-on-one-texel taps are stored as such: weights all 0.
  const auto& taps = table.built().taps;
  EXPECT_EQ(taps[0].texel, 0);
  EXPECT_EQ(taps[0].weights, (std::array<std::uint8_t, 4>{0, 0, 0, 0}));
  EXPECT_EQ(taps[1].texel, 3);
  EXPECT_EQ(taps[1].weights, (std::array<std::uint8_t, 4>{0, 0, 0, 0}));
  EXPECT_EQ(taps[3].texel, 2);  // moved down to the texel that has all the weight
  EXPECT_EQ(taps[3].weights, (std::array<std::uint8_t, 4>{0, 0, 0, 0}));
}

// ChannelOrder::bgra (the player's packed frames): the same eye, red and blue exchanged, byte for
// byte, on a view 20 means wide (the SIMD copy) and one 2 wide (the scalar one).
TEST(CompositeTable, InBgraOrderItIsTheRgbaEyeWithRedAndBlueExchanged) {
  CompositeTable::Recording small;
  small.panel = {4, 1};
  small.reduced = {2, 2};
  small.prefiltered = {2, 2};
  small.horizontal = make_box_axis(2, 0.0, 1.0, 1.0, 1.0, 2, 2.0);
  small.vertical = make_box_axis(2, 0.0, 1.0, 1.0, 1.0, 2, 2.0);
  small.coordinates = {0.25f, 0.25f, 0.75f, 0.75f, 0.4f, 0.6f, 0.3f, 0.7f};
  for (const CompositeTable::Recording& r : {test_recording(), small}) {
    CompositeTable table(r);
    Bytes means(static_cast<std::size_t>(r.reduced[0]) * r.reduced[1] * 4);
    std::mt19937 rng(5);
    for (auto& m : means) m = static_cast<std::uint8_t>(rng());
    const std::size_t stride = static_cast<std::size_t>(r.panel[0]) * 4 + 4;
    Bytes rgba(stride * r.panel[1], 77), bgra(stride * r.panel[1], 77);
    table.render(means.data(), static_cast<std::size_t>(r.reduced[0]) * 4, rgba.data(), stride, ChannelOrder::rgba);
    table.render(means.data(), static_cast<std::size_t>(r.reduced[0]) * 4, bgra.data(), stride, ChannelOrder::bgra);
    Bytes exchanged = rgba;
    for (int y = 0; y < r.panel[1]; ++y)
      for (int x = 0; x < r.panel[0]; ++x) std::swap(exchanged[y * stride + x * 4], exchanged[y * stride + x * 4 + 2]);
    EXPECT_EQ(bgra, exchanged) << "panel " << r.panel[0] << "x" << r.panel[1];
    EXPECT_NE(bgra, rgba);
  }
}

}  // namespace
}  // namespace nelf
