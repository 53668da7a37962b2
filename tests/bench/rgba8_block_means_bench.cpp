// Block means of 8-bit RGBA rows (inputs/view_bytes.hpp), what each live frame goes through before
// it can be shown (a quad-buffer game's eyes, a captured window), against swscale's area scaler
// on the same job (its natural peer, DESIGN.md §10): one 1280×720 eye stored bottom-up, as
// glReadPixels gives it, to 640×360 means of 2×2 blocks.
// usage: nelf_rgba8_block_means_bench [RUNS]
extern "C" {
#include <libavutil/pixfmt.h>
#include <libswscale/swscale.h>
}

#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "bench/bench_timing.hpp"
#include "inputs/view_bytes.hpp"

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::atoi(argv[1]) : 51;
  constexpr int width = 1280, height = 720, out_w = width / 2, out_h = height / 2;
  std::mt19937 random(1);
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(width) * height * 4);
  for (auto& b : rgba) b = static_cast<std::uint8_t>(random());
  std::vector<std::uint8_t> out(static_cast<std::size_t>(out_w) * out_h * 4), means;
  const std::uint8_t* top_row = rgba.data() + static_cast<std::ptrdiff_t>(height - 1) * width * 4;

  SwsContext* sws = sws_getContext(width, height, AV_PIX_FMT_RGBA, out_w, out_h, AV_PIX_FMT_RGBA,
                                   SWS_AREA | SWS_ACCURATE_RND, nullptr, nullptr, nullptr);
  const std::uint8_t* src[4] = {top_row, nullptr, nullptr, nullptr};
  const int src_stride[4] = {-width * 4, 0, 0, 0};
  std::uint8_t* dst[4] = {out.data(), nullptr, nullptr, nullptr};
  const int dst_stride[4] = {out_w * 4, 0, 0, 0};

  const auto [s, o] = nelf::bench::interleaved_medians(
      runs, [&] { sws_scale(sws, src, src_stride, 0, height, dst, dst_stride); },
      [&] {
        means = nelf::rgba8_block_means(top_row, -width * 4, width, height, {2, 2});
      });
  sws_freeContext(sws);
  std::printf("one 1280x720 RGBA8 eye, bottom-up, to 640x360 block means, median of %d runs\n", runs);
  std::printf("swscale (SWS_AREA)  %7.3f ms\n", s);
  std::printf("rgba8_block_means   %7.3f ms\n", o);
  std::printf("ratio               %7.2f (swscale / own)\n", s / o);
}
