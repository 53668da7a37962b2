#include "compositor/overlays/subtitle_overlay.hpp"

#include <algorithm>
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

// `map` (a view's disparity, possibly coarser than the view) with the disparity of a subtitle whose
// copy in this view is `rgba` shifted by `shift` view pixels set where the copy covers a map pixel:
// any view pixel under it at least a quarter opaque, so that thin strokes on a coarse map still count.
void set_subtitle_disparity(ViewDisparity& map, const std::vector<std::uint8_t>& rgba, int width, int height, int shift,
                            float disparity) {
  if (map.width <= 0 || map.height <= 0) return;
  for (int my = 0; my < map.height; ++my) {
    const int y0 = my * height / map.height, y1 = std::max(y0 + 1, (my + 1) * height / map.height);
    for (int mx = 0; mx < map.width; ++mx) {
      const int x0 = mx * width / map.width, x1 = std::max(x0 + 1, (mx + 1) * width / map.width);
      bool covered = false;
      for (int y = y0; y < y1 && !covered; ++y)
        for (int x = x0; x < x1 && !covered; ++x) {
          const int sx = x - shift;
          covered = sx >= 0 && sx < width && rgba[(static_cast<std::size_t>(y) * width + sx) * 4 + 3] >= 64;
        }
      if (covered) map.d[static_cast<std::size_t>(my) * map.width + mx] = disparity;
    }
  }
}

// The known disparities of `map` under the view region [x0, x1) × [y0, y1) of a `width`×`height` view.
void known_disparities(const ViewDisparity& map, int x0, int y0, int x1, int y1, int width, int height,
                       std::vector<float>& into, long& region_pixels) {
  if (map.width <= 0 || map.height <= 0 || width <= 0 || height <= 0) return;
  const int mx0 = std::clamp(static_cast<int>(static_cast<long>(x0) * map.width / width), 0, map.width);
  const int mx1 = std::clamp(static_cast<int>((static_cast<long>(x1) * map.width + width - 1) / width), 0, map.width);
  const int my0 = std::clamp(static_cast<int>(static_cast<long>(y0) * map.height / height), 0, map.height);
  const int my1 =
      std::clamp(static_cast<int>((static_cast<long>(y1) * map.height + height - 1) / height), 0, map.height);
  for (int my = my0; my < my1; ++my)
    for (int mx = mx0; mx < mx1; ++mx) {
      ++region_pixels;
      const float d = map.d[static_cast<std::size_t>(my) * map.width + mx];
      if (std::isfinite(d)) into.push_back(d * static_cast<float>(width) / static_cast<float>(map.width));
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
  if (frame.disparity) {
    // The maps may be shared with other frames (a still's, the matcher's last): changed in a copy.
    auto with_text = std::make_shared<StereoDisparity>(*frame.disparity);
    const auto separation = static_cast<float>(2 * shift);  // view pixels between the two copies
    set_subtitle_disparity(with_text->left, subtitle.rgba, width, height, shift,
                           separation * static_cast<float>(with_text->left.width) / static_cast<float>(width));
    set_subtitle_disparity(with_text->right, right, width, height, -shift,
                           separation * static_cast<float>(with_text->right.width) / static_cast<float>(width));
    frame.disparity = std::move(with_text);
  }
}

std::optional<SubtitleBox> subtitle_box(const SubtitleBitmap& subtitle) {
  SubtitleBox box{subtitle.width, subtitle.height, 0, 0};
  for (const std::vector<std::uint8_t>* rgba : {&subtitle.rgba, &subtitle.right_rgba}) {
    if (rgba->size() != static_cast<std::size_t>(subtitle.width) * subtitle.height * 4) continue;
    for (int y = 0; y < subtitle.height; ++y)
      for (int x = 0; x < subtitle.width; ++x)
        if ((*rgba)[(static_cast<std::size_t>(y) * subtitle.width + x) * 4 + 3] != 0) {
          box.x0 = std::min(box.x0, x);
          box.y0 = std::min(box.y0, y);
          box.x1 = std::max(box.x1, x + 1);
          box.y1 = std::max(box.y1, y + 1);
        }
  }
  if (box.x1 <= box.x0 || box.y1 <= box.y0) return std::nullopt;
  return box;
}

std::optional<double> content_parallax_beneath(const StereoDisparity& disparity, const SubtitleBox& box, int view_width,
                                               int view_height) {
  // As far as either copy can move: half the largest parallax. And a little above and below, where
  // the text's outline and shadow fall.
  const int widen = static_cast<int>(std::ceil(max_sub_parallax_percent / 200.0 * view_width));
  const int lift = std::max(1, view_height / 50);
  const int x0 = std::max(0, box.x0 - widen), x1 = std::min(view_width, box.x1 + widen);
  const int y0 = std::max(0, box.y0 - lift), y1 = std::min(view_height, box.y1 + lift);
  std::vector<float> known;  // in view pixels
  long region = 0;
  known_disparities(disparity.left, x0, y0, x1, y1, view_width, view_height, known, region);
  known_disparities(disparity.right, x0, y0, x1, y1, view_width, view_height, known, region);
  // Below a twentieth known, what is there is too little to say what the text covers.
  if (region == 0 || known.size() * 20 < static_cast<std::size_t>(region)) return std::nullopt;
  const auto nth = known.begin() + static_cast<std::ptrdiff_t>((known.size() - 1) * 95 / 100);
  std::nth_element(known.begin(), nth, known.end());
  return 100.0 * static_cast<double>(*nth) / view_width;
}

}  // namespace nelf
