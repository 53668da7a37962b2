#include "compositor/overlays/calibration_overlay.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace nelf {

Image cover_grid(const Image& pattern, std::array<int, 2> block) {
  Image out(pattern.width() / block[0], pattern.height() / block[1]);
  const float per_block = 1.f / static_cast<float>(block[0] * block[1]);
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) {
      Rgba sum{0.f, 0.f, 0.f, 0.f};
      for (int by = 0; by < block[1]; ++by)
        for (int bx = 0; bx < block[0]; ++bx) {
          const Rgba& q = pattern.at(x * block[0] + bx, y * block[1] + by);
          if (std::max({q.r, q.g, q.b}) < 0.02f) continue;  // black: the movie shows through
          sum.r += q.r;
          sum.g += q.g;
          sum.b += q.b;
          sum.a += 1.f;
        }
      Rgba& o = out.at(x, y);
      o = sum.a > 0.f ? Rgba{sum.r / sum.a, sum.g / sum.a, sum.b / sum.a, sum.a * per_block} : Rgba{0.f, 0.f, 0.f, 0.f};
    }
  return out;
}

void draw_over(std::vector<std::uint8_t>& pixels, const Image& cover, int bits) {
  const std::size_t n = static_cast<std::size_t>(cover.width()) * cover.height();
  const float* p = cover.data();
  for (std::size_t i = 0; i < n; ++i) {
    const float a = p[i * 4 + 3];
    if (a <= 0.f) continue;
    for (std::size_t c = 0; c < 3; ++c) {
      const float grid = std::clamp(p[i * 4 + c], 0.f, 1.f);
      if (bits > 8) {
        std::uint16_t u = 0;
        std::memcpy(&u, &pixels[i * 8 + c * 2], 2);
        u = static_cast<std::uint16_t>(std::lround((u / 65535.f * (1.f - a) + grid * a) * 65535.f));
        std::memcpy(&pixels[i * 8 + c * 2], &u, 2);
      } else {
        pixels[i * 4 + c] =
            static_cast<std::uint8_t>(std::lround((pixels[i * 4 + c] / 255.f * (1.f - a) + grid * a) * 255.f));
      }
    }
  }
}

}  // namespace nelf
