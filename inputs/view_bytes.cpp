#include "inputs/view_bytes.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

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

std::vector<std::uint8_t> rgba8_block_means(const std::uint8_t* first_row, std::ptrdiff_t row_stride, int width,
                                            int height, std::array<int, 2> block, ByteOrder order) {
  const int bx = block[0], by = block[1];
  const int w = width / bx, h = height / by;
  std::vector<std::uint8_t> out(static_cast<std::size_t>(w) * h * 4);
  cv::Mat means(h, w, CV_8UC4, out.data());
  if (bx == 1 && by == 1) {
    for (int y = 0; y < h; ++y)
      std::memcpy(&out[static_cast<std::size_t>(y) * w * 4], first_row + y * row_stride,
                  static_cast<std::size_t>(w) * 4);
    if (order == ByteOrder::rgba) return out;  // as stored, alpha included
  } else {
    // OpenCV's area resize averages whole blocks with SIMD, several times faster than a loop over
    // the bytes: this is time a live frame waits before it can be shown (docs/PERFORMANCE.md).
    // Its rows go down in memory, so a bottom-up image is taken as stored and its means flipped.
    const int used_rows = h * by;
    const bool bottom_up = row_stride < 0;
    const std::uint8_t* lowest =
        bottom_up ? first_row + static_cast<std::ptrdiff_t>(used_rows - 1) * row_stride : first_row;
    const cv::Mat rows(used_rows, w * bx, CV_8UC4, const_cast<std::uint8_t*>(lowest),
                       static_cast<std::size_t>(bottom_up ? -row_stride : row_stride));
    cv::resize(rows, means, means.size(), 0, 0, cv::INTER_AREA);
    if (bottom_up) cv::flip(means, means, 0);
  }
  if (order == ByteOrder::bgrx) cv::cvtColor(means, means, cv::COLOR_BGRA2RGBA);  // in place: a per-pixel swap
  cv::bitwise_or(means, cv::Scalar(0, 0, 0, 255), means);
  return out;
}

}  // namespace nelf
