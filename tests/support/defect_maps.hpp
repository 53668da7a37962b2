#pragma once
// Seeded random defect maps for the tests of the defect compensation: the same map on every
// platform (the raw 32-bit output of std::mt19937 is specified by the standard, unlike the
// distributions).
#include <array>
#include <cstdint>
#include <random>

#include "optics/defect_map.hpp"
#include "optics/mapping.hpp"

namespace nelf::test {

// Each lit pixel of `mapping` (one that shows part of the view) is dead with probability
// `dead_fraction`, otherwise stuck at `stuck_rgb` with probability `stuck_fraction`.
inline DefectMap random_defect_map(const EyeMapping& mapping, double dead_fraction, double stuck_fraction,
                                   std::uint32_t seed, std::array<std::uint8_t, 3> stuck_rgb = {255, 255, 255}) {
  std::mt19937 random(seed);
  constexpr double range = 4294967296.0;  // 2^32
  DefectMap map;
  for (int y = 0; y < mapping.panel[1]; ++y) {
    for (int x = 0; x < mapping.panel[0]; ++x) {
      if (!view_coordinate_at_pixel(mapping, x + 0.5, y + 0.5)) continue;
      const double draw = static_cast<double>(random()) / range;
      if (draw < dead_fraction)
        map.defects.push_back({mapping.eye, x, y, DefectKind::dead, {0, 0, 0}});
      else if (draw < dead_fraction + stuck_fraction)
        map.defects.push_back({mapping.eye, x, y, DefectKind::stuck, stuck_rgb});
    }
  }
  return map;
}

}  // namespace nelf::test
