#include "core/chart_style.hpp"

#include <algorithm>
#include <filesystem>
#include <system_error>

namespace nelf::chart {

Rgb viridis(double t) {
  static constexpr std::array<Rgb, 11> stops = {{{0.267f, 0.005f, 0.329f},
                                                 {0.282f, 0.141f, 0.459f},
                                                 {0.255f, 0.267f, 0.529f},
                                                 {0.208f, 0.373f, 0.553f},
                                                 {0.165f, 0.471f, 0.557f},
                                                 {0.129f, 0.569f, 0.549f},
                                                 {0.133f, 0.659f, 0.518f},
                                                 {0.267f, 0.749f, 0.439f},
                                                 {0.478f, 0.820f, 0.318f},
                                                 {0.741f, 0.875f, 0.149f},
                                                 {0.993f, 0.906f, 0.144f}}};
  const double x = std::clamp(t, 0.0, 1.0) * 10.0;
  const auto i = std::min<std::size_t>(static_cast<std::size_t>(x), 9);
  const float w = static_cast<float>(x - static_cast<double>(i));
  Rgb c;
  for (std::size_t k = 0; k < 3; ++k) c[k] = stops[i][k] * (1.f - w) + stops[i + 1][k] * w;
  return c;
}

std::string font() {
  for (const char* candidate : {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
                                "/usr/share/fonts/TTF/DejaVuSans.ttf", "/usr/share/fonts/dejavu/DejaVuSans.ttf"}) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(candidate, ec)) return candidate;
  }
  return "DejaVuSans";
}

}  // namespace nelf::chart
