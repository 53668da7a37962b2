// The encoder's own RGBA → YUV 4:2:0 BT.709 limited-range conversion: the analytic values of
// primaries, a double-precision reference of the same formula on random pixels (SIMD body and
// scalar edges alike, odd sizes), and swscale, which it replaces, on smooth content.
#include <gtest/gtest.h>

extern "C" {
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "hmz_output/rgba_to_yuv.hpp"

namespace nelf {
namespace {

struct Yuv {
  int width, height;
  std::vector<std::uint8_t> y, u, v;
  Yuv(int w, int h)
      : width(w),
        height(h),
        y(static_cast<std::size_t>(w) * h),
        u(static_cast<std::size_t>((w + 1) / 2) * ((h + 1) / 2)),
        v(u.size()) {}
  YuvPlanes planes() { return {y.data(), u.data(), v.data(), width, (width + 1) / 2, (width + 1) / 2}; }
};

Yuv convert(const std::vector<std::uint8_t>& rgba, int w, int h) {
  Yuv out(w, h);
  rgba_to_yuv420_bt709(rgba.data(), static_cast<std::ptrdiff_t>(w) * 4, w, h, out.planes());
  return out;
}

std::vector<std::uint8_t> filled(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w) * h * 4);
  for (std::size_t i = 0; i < rgba.size(); i += 4) rgba[i] = r, rgba[i + 1] = g, rgba[i + 2] = b, rgba[i + 3] = 255;
  return rgba;
}

// BT.709 limited range from full-range RGB in double precision.
std::array<double, 3> reference(double r, double g, double b) {
  const double kr = 0.2126, kb = 0.0722, kg = 1 - kr - kb;
  const double y = kr * r + kg * g + kb * b;
  return {16 + 219.0 / 255 * y, 128 + 224.0 / 255 * (b - y) / (2 * (1 - kb)),
          128 + 224.0 / 255 * (r - y) / (2 * (1 - kr))};
}

TEST(RgbaToYuv, PrimariesBlackAndWhiteHaveTheirBt709LimitedRangeValues) {
  const struct {
    std::uint8_t r, g, b;
    int y, u, v;
  } cases[] = {{0, 0, 0, 16, 128, 128},  {255, 255, 255, 235, 128, 128}, {255, 0, 0, 63, 102, 240},
               {0, 255, 0, 173, 42, 26}, {0, 0, 255, 32, 240, 118},      {128, 128, 128, 126, 128, 128}};
  for (const auto& c : cases) {
    // 37×5: the SIMD body, the scalar tail and an odd last row.
    const Yuv out = convert(filled(37, 5, c.r, c.g, c.b), 37, 5);
    for (std::uint8_t y : out.y) ASSERT_EQ(y, c.y) << int(c.r) << "," << int(c.g) << "," << int(c.b);
    for (std::uint8_t u : out.u) ASSERT_EQ(u, c.u) << int(c.r) << "," << int(c.g) << "," << int(c.b);
    for (std::uint8_t v : out.v) ASSERT_EQ(v, c.v) << int(c.r) << "," << int(c.g) << "," << int(c.b);
  }
}

TEST(RgbaToYuv, RandomPixelsWithinOneCodeOfTheReferenceAtOddSizes) {
  std::mt19937 random(7);
  for (const auto& [w, h] : {std::pair{64, 32}, {45, 17}, {1, 1}, {18, 3}}) {
    std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w) * h * 4);
    for (auto& byte : rgba) byte = static_cast<std::uint8_t>(random() & 0xff);
    const Yuv out = convert(rgba, w, h);
    const auto at = [&](int x, int y, int c) {
      return double(rgba[(static_cast<std::size_t>(std::min(y, h - 1)) * w + std::min(x, w - 1)) * 4 + c]);
    };
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        ASSERT_LE(std::abs(out.y[y * w + x] - reference(at(x, y, 0), at(x, y, 1), at(x, y, 2))[0]), 1.0)
            << x << "," << y << " of " << w << "x" << h;
    const int cw = (w + 1) / 2;
    for (int cy = 0; cy < (h + 1) / 2; ++cy)
      for (int cx = 0; cx < cw; ++cx) {
        double mean[3] = {0, 0, 0};
        for (int c = 0; c < 3; ++c)
          mean[c] = (at(2 * cx, 2 * cy, c) + at(2 * cx + 1, 2 * cy, c) + at(2 * cx, 2 * cy + 1, c) +
                     at(2 * cx + 1, 2 * cy + 1, c)) /
                    4;
        const auto expected = reference(mean[0], mean[1], mean[2]);
        ASSERT_LE(std::abs(out.u[cy * cw + cx] - expected[1]), 1.0) << cx << "," << cy << " of " << w << "x" << h;
        ASSERT_LE(std::abs(out.v[cy * cw + cx] - expected[2]), 1.0) << cx << "," << cy << " of " << w << "x" << h;
      }
  }
}

TEST(RgbaToYuv, AgreesWithSwscaleOnSmoothContent) {
  const int w = 96, h = 64;
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = &rgba[(static_cast<std::size_t>(y) * w + x) * 4];
      p[0] = static_cast<std::uint8_t>(x * 255 / (w - 1)), p[1] = static_cast<std::uint8_t>(y * 255 / (h - 1));
      p[2] = static_cast<std::uint8_t>(128 + 100 * std::sin((x + y) / 20.0)), p[3] = 255;
    }
  const Yuv ours = convert(rgba, w, h);
  // swscale as the encoder configured it before (full-range RGB to BT.709 limited range).
  SwsContext* sws = sws_getContext(w, h, AV_PIX_FMT_RGBA, w, h, AV_PIX_FMT_YUV420P,
                                   SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, nullptr, nullptr, nullptr);
  ASSERT_NE(sws, nullptr);
  const int* bt709 = sws_getCoefficients(SWS_CS_ITU709);
  sws_setColorspaceDetails(sws, bt709, 1, bt709, 0, 0, 1 << 16, 1 << 16);
  Yuv theirs(w, h);
  std::uint8_t* planes[3] = {theirs.y.data(), theirs.u.data(), theirs.v.data()};
  const int strides[3] = {w, w / 2, w / 2};
  const std::uint8_t* source[1] = {rgba.data()};
  const int source_stride[1] = {w * 4};
  sws_scale(sws, source, source_stride, 0, h, planes, strides);
  sws_freeContext(sws);
  int worst_y = 0, worst_c = 0;
  for (std::size_t i = 0; i < ours.y.size(); ++i) worst_y = std::max(worst_y, std::abs(ours.y[i] - theirs.y[i]));
  // Away from the edges (swscale's chroma filter is wider than a 2×2 block).
  for (int cy = 2; cy < h / 2 - 2; ++cy)
    for (int cx = 2; cx < w / 2 - 2; ++cx)
      for (const auto* plane : {&ours.u, &ours.v}) {
        const auto& other = plane == &ours.u ? theirs.u : theirs.v;
        worst_c = std::max(worst_c, std::abs((*plane)[cy * (w / 2) + cx] - other[cy * (w / 2) + cx]));
      }
  EXPECT_LE(worst_y, 1);
  EXPECT_LE(worst_c, 2);
}

}  // namespace
}  // namespace nelf
