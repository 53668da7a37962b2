#include "hmz_output/packing.hpp"

#include <fmt/format.h>
#include <algorithm>

namespace nelf {
namespace {

// Copies `eye` into the area_w x area_h area of `frame` at (area_x, area_y), centred 1:1: borders
// stay as they are (black) when the eye is smaller, the eye is cropped evenly when it is larger.
void blit_centred(Image& frame, const Image& eye, int area_x, int area_y, int area_w, int area_h) {
  const int dx = (area_w - eye.width()) / 2, dy = (area_h - eye.height()) / 2;
  const int x_begin = std::max(0, dx), x_end = std::min(area_w, dx + eye.width());
  const int y_begin = std::max(0, dy), y_end = std::min(area_h, dy + eye.height());
  for (int y = y_begin; y < y_end; ++y) {
    const Rgba* src = &eye.at(x_begin - dx, y - dy);
    std::copy(src, src + (x_end - x_begin), &frame.at(area_x + x_begin, area_y + y));
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
  const int w = left.width(), h = left.height();
  Image frame(signal.packed_width(w), signal.packed_height(h));  // black, alpha 1
  for (Eye eye : {Eye::left, Eye::right})
    if (const auto area = eye_area(signal, eye, w, h))
      blit_centred(frame, eye == Eye::left ? left : right, area->x, area->y, area->width, area->height);
  return frame;
}

}  // namespace nelf
