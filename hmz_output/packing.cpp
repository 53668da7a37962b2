#include "hmz_output/packing.hpp"

#include <fmt/format.h>

namespace nelf {

std::optional<EyeArea> eye_area(const Signal& signal, Eye eye, int eye_w, int eye_h) {
  const bool right = eye == Eye::right;
  switch (signal.kind) {
    case SignalKind::hdmi_frame_packing:
      return EyeArea{0, right ? signal.right_eye_first_row() : 0, signal.eye_width, signal.eye_height};
    case SignalKind::side_by_side:
      return EyeArea{right ? eye_w : 0, 0, eye_w, eye_h};
    case SignalKind::top_bottom:
      return EyeArea{0, right ? eye_h : 0, eye_w, eye_h};
    case SignalKind::single_eye:
      if (signal.eye != eye) return std::nullopt;
      return EyeArea{0, 0, eye_w, eye_h};
  }
  return std::nullopt;
}

Image pack_eyes(const Signal& signal, const Image& left, const Image& right) {
  if (left.empty() || right.empty()) throw std::invalid_argument("pack_eyes: empty eye image");
  if (left.width() != right.width() || left.height() != right.height())
    throw std::invalid_argument(fmt::format("pack_eyes: eye images differ in size ({}x{} and {}x{})", left.width(),
                                            left.height(), right.width(), right.height()));
  // The one placement: the packed layout's, as every video frame's (core/packed_layout.hpp).
  return place_eyes(packed_layout(signal, {left.width(), left.height()}), EyeImages{left, right});
}

PackedLayout packed_layout(const Signal& signal, std::array<int, 2> eye) {
  PackedLayout layout;
  layout.packed = {signal.packed_width(eye[0]), signal.packed_height(eye[1])};
  layout.eye = eye;
  for (Eye e : {Eye::left, Eye::right}) {
    const auto area = eye_area(signal, e, eye[0], eye[1]);
    if (!area) continue;
    const int i = static_cast<int>(e);
    layout.areas[i] = area;
    // C++ division truncates toward zero: a larger eye is cropped by the same amount on both sides.
    layout.origins[i] = std::pair{area->x + (area->width - eye[0]) / 2, area->y + (area->height - eye[1]) / 2};
  }
  return layout;
}

}  // namespace nelf
