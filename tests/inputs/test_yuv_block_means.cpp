// inputs/yuv_block_means: block means of 8-bit 4:2:0 straight to RGBA8, against swscale's area
// scaler (what VideoSource used before, and still uses for other formats) and against exact colours;
// of 10-bit 4:2:0 to dithered RGBA8, against the 8-bit means and the exact mean.
#include <gtest/gtest.h>

extern "C" {
#include <libavutil/pixfmt.h>
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <vector>

#include "inputs/yuv_block_means.hpp"

namespace nelf {
namespace {

struct Frame420 {
  int width, height;
  std::vector<std::uint8_t> y, u, v;
  Frame420(int w, int h)
      : width(w),
        height(h),
        y(static_cast<std::size_t>(w) * h),
        u(static_cast<std::size_t>(w / 2) * (h / 2)),
        v(static_cast<std::size_t>(w / 2) * (h / 2)) {}
  Yuv420Planes planes() const {
    return {
        .y = y.data(), .u = u.data(), .v = v.data(), .y_stride = width, .u_stride = width / 2, .v_stride = width / 2};
  }
};

// Smooth gradients plus noise, inside the legal range, like decoded video.
Frame420 test_frame(int w, int h, unsigned seed) {
  Frame420 f(w, h);
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> noise(-12, 12);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      f.y[static_cast<std::size_t>(y) * w + x] =
          static_cast<std::uint8_t>(std::clamp(16 + (x * 219) / w + noise(random) / 2, 16, 235));
  for (int y = 0; y < h / 2; ++y)
    for (int x = 0; x < w / 2; ++x) {
      f.u[static_cast<std::size_t>(y) * (w / 2) + x] =
          static_cast<std::uint8_t>(std::clamp(40 + (y * 170) / (h / 2) + noise(random), 16, 240));
      f.v[static_cast<std::size_t>(y) * (w / 2) + x] =
          static_cast<std::uint8_t>(std::clamp(200 - (x * 150) / (w / 2) + noise(random), 16, 240));
    }
  return f;
}

// swscale's area scaler as VideoSource configured it.
std::vector<std::uint8_t> with_swscale(const Frame420& f, int block_x, int block_y, int colorspace, bool full_range) {
  const int out_w = f.width / block_x, out_h = f.height / block_y;
  SwsContext* sws =
      sws_getContext(f.width, f.height, AV_PIX_FMT_YUV420P, out_w, out_h, AV_PIX_FMT_RGBA,
                     SWS_AREA | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT | SWS_FULL_CHR_H_INP, nullptr, nullptr, nullptr);
  EXPECT_NE(sws, nullptr);
  const int* coefficients = sws_getCoefficients(colorspace);
  sws_setColorspaceDetails(sws, coefficients, full_range ? 1 : 0, coefficients, 1, 0, 1 << 16, 1 << 16);
  std::vector<std::uint8_t> out(static_cast<std::size_t>(out_w) * out_h * 4);
  const std::uint8_t* src[4] = {f.y.data(), f.u.data(), f.v.data(), nullptr};
  const int src_stride[4] = {f.width, f.width / 2, f.width / 2, 0};
  std::uint8_t* dst[4] = {out.data(), nullptr, nullptr, nullptr};
  const int dst_stride[4] = {out_w * 4, 0, 0, 0};
  EXPECT_EQ(sws_scale(sws, src, src_stride, 0, f.height, dst, dst_stride), out_h);
  sws_freeContext(sws);
  return out;
}

std::vector<std::uint8_t> with_block_means(const Frame420& f, int block_x, int block_y, int colorspace,
                                           bool full_range) {
  const int out_w = f.width / block_x, out_h = f.height / block_y;
  std::vector<std::uint8_t> out(static_cast<std::size_t>(out_w) * out_h * 4);
  yuv420_block_means(f.planes(), f.width, f.height, block_x, block_y,
                     yuv_to_rgb_from_sws(sws_getCoefficients(colorspace), full_range), out.data(),
                     static_cast<std::size_t>(out_w) * 4);
  return out;
}

TEST(YuvBlockMeans, AgreeWithSwscalesAreaScaler) {
  for (const auto& [bx, by] : {std::pair{2, 4}, std::pair{2, 2}, std::pair{4, 4}, std::pair{6, 2}})
    for (const int colorspace : {SWS_CS_ITU601, SWS_CS_ITU709, SWS_CS_BT2020})
      for (const bool full_range : {false, true}) {
        SCOPED_TRACE(::testing::Message() << bx << "x" << by << " colorspace " << colorspace << " full " << full_range);
        const Frame420 f = test_frame(bx * 60, by * 34, 7u + static_cast<unsigned>(bx * by));
        const auto expected = with_swscale(f, bx, by, colorspace, full_range);
        const auto got = with_block_means(f, bx, by, colorspace, full_range);
        ASSERT_EQ(got.size(), expected.size());
        int worst = 0;
        double sum = 0;
        for (std::size_t i = 0; i < got.size(); ++i) {
          const int d = std::abs(int(got[i]) - int(expected[i]));
          worst = std::max(worst, d);
          sum += d;
        }
        // swscale interpolates chroma to full resolution before averaging and rounds in fixed
        // point: at most a code apart, and that rarely (measured: mean 0.0002-0.004 codes).
        EXPECT_LE(worst, 1);
        EXPECT_LT(sum / got.size(), 0.05);
      }
}

TEST(YuvBlockMeans, FlatColoursComeOutExact) {
  // BT.709 limited range: (Y, U, V) of black, white, and 75 % red, green, blue (ITU-R BT.709 bars).
  struct Case {
    std::uint8_t y, u, v;
    int r, g, b;
  };
  for (const Case c : {Case{16, 128, 128, 0, 0, 0}, Case{235, 128, 128, 255, 255, 255}, Case{51, 109, 212, 191, 0, 0},
                       Case{133, 63, 52, 0, 191, 0}, Case{28, 212, 120, 0, 0, 191}}) {
    Frame420 f(8, 8);
    std::fill(f.y.begin(), f.y.end(), c.y);
    std::fill(f.u.begin(), f.u.end(), c.u);
    std::fill(f.v.begin(), f.v.end(), c.v);
    const auto got = with_block_means(f, 2, 4, SWS_CS_ITU709, false);
    for (std::size_t i = 0; i < got.size(); i += 4) {
      EXPECT_NEAR(got[i], c.r, 1) << int(c.y) << "," << int(c.u) << "," << int(c.v);
      EXPECT_NEAR(got[i + 1], c.g, 1);
      EXPECT_NEAR(got[i + 2], c.b, 1);
      EXPECT_EQ(got[i + 3], 255);
    }
  }
}

TEST(YuvBlockMeans, EachBlockIsItsOwnMean) {
  // Blocks of distinct flat values: no block leaks into its neighbour (the chroma block is the
  // luma block's own samples).
  Frame420 f(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) f.y[static_cast<std::size_t>(y) * 8 + x] = static_cast<std::uint8_t>(x < 4 ? 16 : 235);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      f.u[static_cast<std::size_t>(y) * 4 + x] = 128;
      f.v[static_cast<std::size_t>(y) * 4 + x] = static_cast<std::uint8_t>(y < 2 ? 128 : 240);
    }
  const auto got = with_block_means(f, 4, 4, SWS_CS_ITU709, false);  // 2x2 blocks out
  ASSERT_EQ(got.size(), 16u);
  EXPECT_EQ(got[0], 0);        // top left: black
  EXPECT_EQ(got[4 + 1], 255);  // top right: white
  EXPECT_GT(got[8 + 0], 100);  // bottom left: black with V = 240, red
  EXPECT_EQ(got[8 + 2], 0);
  EXPECT_TRUE(yuv420_block_means_supported(2, 4));
  EXPECT_FALSE(yuv420_block_means_supported(3, 4));
  EXPECT_FALSE(yuv420_block_means_supported(1, 2));
}

// The 10-bit samples of `f` (8-bit values times 4, plus `extra` quarter codes on luma).
struct Frame420Deep {
  int width, height;
  std::vector<std::uint16_t> y, u, v;
  Frame420Deep(const Frame420& f, int extra)
      : width(f.width), height(f.height), y(f.y.size()), u(f.u.size()), v(f.v.size()) {
    for (std::size_t i = 0; i < y.size(); ++i) y[i] = static_cast<std::uint16_t>(f.y[i] * 4 + extra);
    for (std::size_t i = 0; i < u.size(); ++i) u[i] = static_cast<std::uint16_t>(f.u[i] * 4);
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint16_t>(f.v[i] * 4);
  }
  std::vector<std::uint8_t> block_means(int bx, int by) const {
    const int out_w = width / bx, out_h = height / by;
    std::vector<std::uint8_t> out(static_cast<std::size_t>(out_w) * out_h * 4);
    const Yuv420Planes16 planes{.y = y.data(),
                                .u = u.data(),
                                .v = v.data(),
                                .y_stride = width,
                                .u_stride = width / 2,
                                .v_stride = width / 2,
                                .bits = 10};
    yuv420_block_means(planes, width, height, bx, by, yuv_to_rgb_from_sws(sws_getCoefficients(SWS_CS_ITU709), false),
                       out.data(), static_cast<std::size_t>(out_w) * 4);
    return out;
  }
};

TEST(YuvBlockMeans, TenBitMeansAreTheEightBitOnesDitheredWithinACode) {
  const Frame420 f = test_frame(2 * 64, 4 * 32, 3u);
  const auto eight = with_block_means(f, 2, 4, SWS_CS_ITU709, false);
  const auto ten = Frame420Deep(f, 0).block_means(2, 4);
  ASSERT_EQ(ten.size(), eight.size());
  for (std::size_t i = 0; i < ten.size(); ++i) ASSERT_LE(std::abs(int(ten[i]) - int(eight[i])), 1) << i;
}

TEST(YuvBlockMeans, TenBitPrecisionSurvivesAsDither) {
  // Flat grey a quarter of a code above 8-bit Y = 128: rounding alone would give one value
  // everywhere; the dither's 4×4 pattern averages to the exact colour.
  Frame420 flat(64, 64);
  std::fill(flat.y.begin(), flat.y.end(), std::uint8_t{128});
  std::fill(flat.u.begin(), flat.u.end(), std::uint8_t{128});
  std::fill(flat.v.begin(), flat.v.end(), std::uint8_t{128});
  const double exact = (128.25 - 16.0) * 255.0 / 219.0;  // limited range grey, in 8-bit RGB codes
  const auto out = Frame420Deep(flat, 1).block_means(2, 2);
  double sum = 0;
  int lowest = 255, highest = 0;
  for (std::size_t i = 0; i < out.size(); i += 4) {
    sum += out[i];
    lowest = std::min(lowest, int(out[i]));
    highest = std::max(highest, int(out[i]));
  }
  EXPECT_NEAR(sum / (out.size() / 4), exact, 0.07);
  EXPECT_EQ(highest - lowest, 1);  // two neighbouring codes, in the pattern
}

}  // namespace
}  // namespace nelf
