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

Image pack_eyes(const Signal& signal, const Image& left, const Image& right) {
  if (left.empty() || right.empty()) throw std::invalid_argument("pack_eyes: empty eye image");
  if (left.width() != right.width() || left.height() != right.height())
    throw std::invalid_argument(fmt::format("pack_eyes: eye images differ in size ({}x{} and {}x{})", left.width(),
                                            left.height(), right.width(), right.height()));
  const int w = left.width(), h = left.height();
  Image frame(signal.packed_width(w), signal.packed_height(h));  // black, alpha 1
  switch (signal.kind) {
    case SignalKind::hdmi_frame_packing:
      blit_centred(frame, left, 0, 0, signal.eye_width, signal.eye_height);
      blit_centred(frame, right, 0, signal.right_eye_first_row(), signal.eye_width, signal.eye_height);
      break;
    case SignalKind::side_by_side:
      blit_centred(frame, left, 0, 0, w, h);
      blit_centred(frame, right, w, 0, w, h);
      break;
    case SignalKind::top_bottom:
      blit_centred(frame, left, 0, 0, w, h);
      blit_centred(frame, right, 0, h, w, h);
      break;
    case SignalKind::single_eye:
      blit_centred(frame, signal.eye == Eye::left ? left : right, 0, 0, w, h);
      break;
  }
  return frame;
}

}  // namespace nelf
