// Block means of 8-bit 4:2:0 video to RGBA8 (inputs/yuv_block_means.hpp) against swscale's area
// scaler configured as VideoSource used it for the same job (its natural peer, DESIGN.md §10): one
// 960×1080 eye of a half side-by-side 1080p frame to 480×270 block means (2×4 blocks), BT.709.
// usage: nelf_yuv_block_means_bench [RUNS]
extern "C" {
#include <libavutil/pixfmt.h>
#include <libswscale/swscale.h>
}

#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "bench/bench_timing.hpp"
#include "inputs/yuv_block_means.hpp"

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::atoi(argv[1]) : 51;
  constexpr int width = 960, height = 1080, bx = 2, by = 4, out_w = width / bx, out_h = height / by;
  std::mt19937 random(1);
  std::vector<std::uint8_t> y(width * height), u(width * height / 4), v(width * height / 4);
  for (auto& b : y) b = static_cast<std::uint8_t>(16 + random() % 220);
  for (auto& b : u) b = static_cast<std::uint8_t>(16 + random() % 225);
  for (auto& b : v) b = static_cast<std::uint8_t>(16 + random() % 225);
  std::vector<std::uint8_t> out(out_w * out_h * 4);

  SwsContext* sws =
      sws_getContext(width, height, AV_PIX_FMT_YUV420P, out_w, out_h, AV_PIX_FMT_RGBA,
                     SWS_AREA | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT | SWS_FULL_CHR_H_INP, nullptr, nullptr, nullptr);
  const int* coefficients = sws_getCoefficients(SWS_CS_ITU709);
  sws_setColorspaceDetails(sws, coefficients, 0, coefficients, 1, 0, 1 << 16, 1 << 16);
  const std::uint8_t* src[4] = {y.data(), u.data(), v.data(), nullptr};
  const int src_stride[4] = {width, width / 2, width / 2, 0};
  std::uint8_t* dst[4] = {out.data(), nullptr, nullptr, nullptr};
  const int dst_stride[4] = {out_w * 4, 0, 0, 0};
  const nelf::YuvToRgb matrix = nelf::yuv_to_rgb_from_sws(coefficients, false);
  const nelf::Yuv420Planes planes{
      .y = y.data(), .u = u.data(), .v = v.data(), .y_stride = width, .u_stride = width / 2, .v_stride = width / 2};

  const auto [s, o] = nelf::bench::interleaved_medians(
      runs, [&] { sws_scale(sws, src, src_stride, 0, height, dst, dst_stride); },
      [&] { nelf::yuv420_block_means(planes, width, height, bx, by, matrix, out.data(), out_w * 4); });
  sws_freeContext(sws);
  std::printf("one 960x1080 eye to 480x270 RGBA8 block means, median of %d runs\n", runs);
  std::printf("swscale (SWS_AREA, full chroma) %7.3f ms\n", s);
  std::printf("yuv420_block_means              %7.3f ms\n", o);
  std::printf("ratio                           %7.2f (swscale / own)\n", s / o);
}
