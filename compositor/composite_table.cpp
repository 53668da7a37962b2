#include "compositor/composite_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace nelf {

namespace {

std::uint8_t to_unorm8(float value) {
  // GL's float → unorm8 conversion: clamp, scale by 255, round to nearest.
  return static_cast<std::uint8_t>(std::clamp(value, 0.f, 255.f) + 0.5f);
}

}  // namespace

// The three colour channels of `tap` on `image` (rows `image_row` bytes apart), times 65536.
inline void CompositeTable::filter(const std::uint8_t* image, std::size_t image_row, const Tap& tap,
                                   unsigned out[3]) {
  const std::uint8_t* p = image + 4 * static_cast<std::size_t>(tap.texel);
  const std::uint8_t* q = p + 4 * tap.right;
  const std::uint8_t* r = p + tap.down * image_row;
  const std::uint8_t* s = r + 4 * tap.right;
  const unsigned fx = tap.fx, fy = tap.fy, gx = 256 - fx, gy = 256 - fy;
  for (int c = 0; c < 3; ++c) out[c] = (p[c] * gx + q[c] * fx) * gy + (r[c] * gx + s[c] * fx) * fy;
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
  if (r.coordinates.size() != 2 * pixels || (!r.border_parts.empty() && r.border_parts.size() != 16 * pixels) ||
      horizontal_.first.size() != static_cast<std::size_t>(prefiltered_[0]) ||
      vertical_.first.size() != static_cast<std::size_t>(prefiltered_[1]))
    throw std::invalid_argument("CompositeTable: the recording's sizes do not match");
  taps_.resize(pixels);
  for (std::size_t i = 0; i < pixels; ++i) taps_[i] = make_tap(r.coordinates[2 * i], r.coordinates[2 * i + 1]);
  for (std::size_t i = 0; !r.border_parts.empty() && i < pixels; ++i) {
    const float* parts = &r.border_parts[16 * i];
    if (parts[3] == 0.f) continue;  // not covered by a border strip
    BorderPixel b;
    b.pixel = static_cast<std::int32_t>(i);
    for (int k = 0; k < 4; ++k) {
      b.weights[k] = parts[4 * k + 2];
      if (b.weights[k] > 0.f) b.taps[k] = make_tap(parts[4 * k], parts[4 * k + 1]);
    }
    borders_.push_back(b);
  }
  input_.resize(static_cast<std::size_t>(reduced_[0]) * reduced_[1] * 4);
  across_.resize(static_cast<std::size_t>(prefiltered_[0]) * reduced_[1] * 4);
  image_.resize(static_cast<std::size_t>(prefiltered_[0]) * prefiltered_[1] * 4);
}

CompositeTable::Tap CompositeTable::make_tap(float u, float v) const {
  Tap tap;
  if (u < 0.f || v < 0.f) return tap;  // the map's "black"
  // GL_LINEAR with GL_CLAMP_TO_EDGE: texel centres at (i + ½) / size; each of the four texels
  // clamped into the texture on its own.
  const double size[2] = {static_cast<double>(prefiltered_[0]), static_cast<double>(prefiltered_[1])};
  int lo[2], step[2], fraction[2];
  const double coordinate[2] = {u * size[0] - 0.5, v * size[1] - 0.5};
  for (int a = 0; a < 2; ++a) {
    int i = static_cast<int>(std::floor(coordinate[a]));
    int f = static_cast<int>(std::lround((coordinate[a] - i) * 256.0));
    if (f == 256) ++i, f = 0;
    const int last = prefiltered_[a] - 1;
    lo[a] = std::clamp(i, 0, last);
    step[a] = std::clamp(i + 1, 0, last) - lo[a];
    fraction[a] = f;
  }
  tap.texel = lo[1] * prefiltered_[0] + lo[0];
  tap.fx = static_cast<std::uint8_t>(fraction[0]);
  tap.fy = static_cast<std::uint8_t>(fraction[1]);
  tap.right = static_cast<std::uint8_t>(step[0]);
  tap.down = static_cast<std::uint8_t>(step[1]);
  return tap;
}

void CompositeTable::box_pass() {
  // Along x: input_ (reduced) → across_ (prefiltered width, reduced height).
  const int in_w = reduced_[0], rows = reduced_[1], out_w = prefiltered_[0], out_h = prefiltered_[1];
  for (int y = 0; y < rows; ++y) {
    const std::uint8_t* in = &input_[static_cast<std::size_t>(y) * in_w * 4];
    std::uint8_t* out = &across_[static_cast<std::size_t>(y) * out_w * 4];
    for (int x = 0; x < out_w; ++x) {
      float r = 0.f, g = 0.f, b = 0.f;
      const std::uint8_t* cell = in + 4 * horizontal_.first[x];
      for (int k = horizontal_.begin[x]; k < horizontal_.begin[x + 1]; ++k, cell += 4) {
        const float w = horizontal_.weights[k];
        r += w * cell[0], g += w * cell[1], b += w * cell[2];
      }
      out[4 * x] = to_unorm8(r), out[4 * x + 1] = to_unorm8(g), out[4 * x + 2] = to_unorm8(b), out[4 * x + 3] = 255;
    }
  }
  // Along y: across_ → image_, a row at a time (the weights are per output row).
  std::vector<float> sum(static_cast<std::size_t>(out_w) * 3);
  for (int y = 0; y < out_h; ++y) {
    std::fill(sum.begin(), sum.end(), 0.f);
    for (int k = vertical_.begin[y], i = vertical_.first[y]; k < vertical_.begin[y + 1]; ++k, ++i) {
      const float w = vertical_.weights[k];
      const std::uint8_t* in = &across_[static_cast<std::size_t>(i) * out_w * 4];
      for (int x = 0; x < out_w; ++x)
        sum[3 * x] += w * in[4 * x], sum[3 * x + 1] += w * in[4 * x + 1], sum[3 * x + 2] += w * in[4 * x + 2];
    }
    std::uint8_t* out = &image_[static_cast<std::size_t>(y) * out_w * 4];
    for (int x = 0; x < out_w; ++x) {
      out[4 * x] = to_unorm8(sum[3 * x]), out[4 * x + 1] = to_unorm8(sum[3 * x + 1]);
      out[4 * x + 2] = to_unorm8(sum[3 * x + 2]), out[4 * x + 3] = 255;
    }
  }
}

void CompositeTable::render(const std::uint8_t* reduced, std::size_t reduced_stride, std::uint8_t* out,
                            std::size_t out_stride) {
  const std::size_t row_bytes = static_cast<std::size_t>(reduced_[0]) * 4;
  for (int y = 0; y < reduced_[1]; ++y)
    std::memcpy(&input_[y * row_bytes], reduced + static_cast<std::size_t>(y) * reduced_stride, row_bytes);
  box_pass();

  // Pass 1: one bilinear tap per pixel, 8-bit weights as llvmpipe's RGBA8 filtering.
  const std::uint8_t* image = image_.data();
  const std::size_t image_row = static_cast<std::size_t>(prefiltered_[0]) * 4;
  const int width = panel_[0];
  for (int y = 0; y < panel_[1]; ++y) {
    const Tap* tap = &taps_[static_cast<std::size_t>(y) * width];
    std::uint8_t* o = out + static_cast<std::size_t>(y) * out_stride;
    for (int x = 0; x < width; ++x, ++tap, o += 4) {
      if (tap->texel < 0) {
        o[0] = o[1] = o[2] = 0, o[3] = 255;
        continue;
      }
      unsigned v[3];
      filter(image, image_row, *tap, v);
      for (int c = 0; c < 3; ++c) o[c] = static_cast<std::uint8_t>((v[c] + 32768) >> 16);
      o[3] = 255;
    }
  }

  // Pass 2: the pixels along the elemental-image borders, each part of the aperture through its lens.
  for (const BorderPixel& b : borders_) {
    float sum[3] = {0.f, 0.f, 0.f};
    for (int k = 0; k < 4; ++k) {
      const Tap& tap = b.taps[k];
      if (b.weights[k] <= 0.f || tap.texel < 0) continue;
      unsigned v[3];
      filter(image, image_row, tap, v);
      for (int c = 0; c < 3; ++c) sum[c] += b.weights[k] * static_cast<float>(v[c]) * (1.f / 65536.f);
    }
    std::uint8_t* o = out + static_cast<std::size_t>(b.pixel / width) * out_stride + 4 * (b.pixel % width);
    o[0] = to_unorm8(sum[0]), o[1] = to_unorm8(sum[1]), o[2] = to_unorm8(sum[2]), o[3] = 255;
  }
}

}  // namespace nelf
