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

}  // namespace nelf
