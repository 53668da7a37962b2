#include "compositor/overlays/subtitle_overlay.hpp"

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace nelf {
namespace {

template <typename Channel>
void draw_shifted(std::vector<std::uint8_t>& view, int width, int height, const std::vector<std::uint8_t>& subtitle,
                  int shift) {
  constexpr int kMax = sizeof(Channel) == 1 ? 255 : 65535;
  constexpr int kScale = kMax / 255;  // 8-bit subtitle values to the view's channel range
  auto* pixels = reinterpret_cast<Channel*>(view.data());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int sx = x - shift;
      if (sx < 0 || sx >= width) continue;
      const std::uint8_t* s = &subtitle[(static_cast<std::size_t>(y) * width + sx) * 4];
      const int a = s[3];
      if (a == 0) continue;
      Channel* d = &pixels[(static_cast<std::size_t>(y) * width + x) * 4];
      for (int c = 0; c < 3; ++c)
        d[c] = static_cast<Channel>(s[c] * kScale + (static_cast<long>(d[c]) * (255 - a) + 127) / 255);
      d[3] = static_cast<Channel>(kMax);
    }
}

}  // namespace

std::array<int, 2> subtitle_canvas(const StereoVideoFrame& frame) {
  return {frame.width / frame.block[0], frame.height / frame.block[1]};
}

int subtitle_shift(double parallax_percent, int width) {
  return static_cast<int>(std::lround(parallax_percent / 200.0 * width));
}

void draw_subtitles(StereoVideoFrame& frame, const SubtitleBitmap& subtitle, double parallax_percent) {
  if (subtitle.empty()) return;
  const auto [width, height] = subtitle_canvas(frame);
  if (subtitle.width != width || subtitle.height != height ||
      subtitle.rgba.size() != static_cast<std::size_t>(width) * height * 4 ||
      (!subtitle.right_rgba.empty() && subtitle.right_rgba.size() != subtitle.rgba.size()))
    throw std::invalid_argument("draw_subtitles: the subtitle is not the size of the views");
  const int shift = subtitle_shift(parallax_percent, width);
  const std::vector<std::uint8_t>& right = subtitle.right_rgba.empty() ? subtitle.rgba : subtitle.right_rgba;
  if (frame.bits > 8) {
    draw_shifted<std::uint16_t>(frame.left, width, height, subtitle.rgba, shift);
    draw_shifted<std::uint16_t>(frame.right, width, height, right, -shift);
  } else {
    draw_shifted<std::uint8_t>(frame.left, width, height, subtitle.rgba, shift);
    draw_shifted<std::uint8_t>(frame.right, width, height, right, -shift);
  }
}

}  // namespace nelf
