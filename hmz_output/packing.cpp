#include "hmz_output/packing.hpp"

#include <fmt/format.h>
#include <algorithm>

namespace nelf {
namespace {

// Copies `eye` into `frame` with its top-left corner at `origin`, clipped to `area`: borders stay
// as they are (black) when the eye is smaller, the eye is cropped evenly when it is larger.
void blit_centred(Image& frame, const Image& eye, const EyeArea& area, std::pair<int, int> origin) {
  const int dx = origin.first - area.x, dy = origin.second - area.y;
  const int x_begin = std::max(0, dx), x_end = std::min(area.width, dx + eye.width());
  const int y_begin = std::max(0, dy), y_end = std::min(area.height, dy + eye.height());
  for (int y = y_begin; y < y_end; ++y) {
    const Rgba* src = &eye.at(x_begin - dx, y - dy);
    std::copy(src, src + (x_end - x_begin), &frame.at(area.x + x_begin, area.y + y));
  }
}

}  // namespace

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
  const PackedLayout layout = packed_layout(signal, {left.width(), left.height()});
  Image frame(layout.packed[0], layout.packed[1]);  // black, alpha 1
  for (int e = 0; e < 2; ++e)
    if (layout.areas[e]) blit_centred(frame, e == 0 ? left : right, *layout.areas[e], *layout.origins[e]);
  return frame;
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
