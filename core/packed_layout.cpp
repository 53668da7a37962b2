#include "core/packed_layout.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "core/user_error.hpp"

namespace nelf {

void require_eyes_fit(const PackedLayout& layout, std::string_view profile_name, std::string_view signal_name,
                      std::string_view advice) {
  for (const auto& area : layout.areas)
    if (area && (layout.eye[0] > area->width || layout.eye[1] > area->height))
      throw UserError(
          fmt::format("the {}x{} panel of profile {} does not fit the {}x{} eye area of signal {}{}", layout.eye[0],
                      layout.eye[1], profile_name, area->width, area->height, signal_name, advice),
          2);
}

Image place_eyes(const PackedLayout& layout, const EyeImages& eyes) {
  for (const Image& eye : eyes)
    if (eye.width() != layout.eye[0] || eye.height() != layout.eye[1])
      throw std::invalid_argument(fmt::format("place_eyes: a {}x{} eye image for a layout of {}x{} eyes", eye.width(),
                                              eye.height(), layout.eye[0], layout.eye[1]));
  Image frame(layout.packed[0], layout.packed[1]);  // black, alpha 1
  for (std::size_t e = 0; e < 2; ++e) {
    if (!layout.areas[e]) continue;
    const EyeArea& area = *layout.areas[e];
    const Image& eye = eyes[e];
    // Clipped to the area: borders stay black when the eye is smaller, the eye is cropped evenly
    // (the origin lies outside the area) when it is larger.
    const int dx = layout.origins[e]->first - area.x, dy = layout.origins[e]->second - area.y;
    const int x_begin = std::max(0, dx), x_end = std::min(area.width, dx + eye.width());
    const int y_begin = std::max(0, dy), y_end = std::min(area.height, dy + eye.height());
    for (int y = y_begin; y < y_end; ++y) {
      const Rgba* src = &eye.at(x_begin - dx, y - dy);
      std::copy(src, src + (x_end - x_begin), &frame.at(area.x + x_begin, area.y + y));
    }
  }
  return frame;
}

}  // namespace nelf
