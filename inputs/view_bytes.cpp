#include "inputs/view_bytes.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace nelf {

std::vector<std::uint8_t> view_bytes(const Image& image, int bits) {
  const std::size_t n = static_cast<std::size_t>(image.width()) * image.height() * 4;
  const float* p = image.data();
  std::vector<std::uint8_t> out(n * (bits > 8 ? 2 : 1));
  for (std::size_t i = 0; i < n; ++i) {
    const float v = std::clamp(p[i], 0.f, 1.f);
    if (bits > 8) {
      const auto value = static_cast<std::uint16_t>(std::lround(v * 65535.f));
      std::memcpy(&out[2 * i], &value, 2);
    } else {
      out[i] = static_cast<std::uint8_t>(std::lround(v * 255.f));
    }
  }
  return out;
}

std::vector<std::uint8_t> rgba8_block_means(const std::uint8_t* first_row, std::ptrdiff_t row_stride, int width,
                                            int height, std::array<int, 2> block) {
  const int bx = block[0], by = block[1];
  const int w = width / bx, h = height / by;
  std::vector<std::uint8_t> out(static_cast<std::size_t>(w) * h * 4);
  if (bx == 1 && by == 1) {
    for (int y = 0; y < h; ++y)
      std::memcpy(&out[static_cast<std::size_t>(y) * w * 4], first_row + y * row_stride,
                  static_cast<std::size_t>(w) * 4);
    return out;
  }
  const unsigned n = static_cast<unsigned>(bx * by);
  std::vector<unsigned> sums(static_cast<std::size_t>(w) * 3);
  for (int y = 0; y < h; ++y) {
    std::fill(sums.begin(), sums.end(), 0u);
    for (int j = 0; j < by; ++j) {
      const std::uint8_t* row = first_row + static_cast<std::ptrdiff_t>(y * by + j) * row_stride;
      for (int x = 0; x < w; ++x)
        for (int i = 0; i < bx; ++i, row += 4) {
          sums[x * 3] += row[0];
          sums[x * 3 + 1] += row[1];
          sums[x * 3 + 2] += row[2];
        }
    }
    std::uint8_t* dst = &out[static_cast<std::size_t>(y) * w * 4];
    for (int x = 0; x < w; ++x, dst += 4) {
      for (int c = 0; c < 3; ++c) dst[c] = static_cast<std::uint8_t>((sums[x * 3 + c] + n / 2) / n);
      dst[3] = 255;
    }
  }
  return out;
}

}  // namespace nelf
