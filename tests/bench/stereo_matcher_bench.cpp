// The estimated depth (inputs/stereo_matcher.hpp) of one 1080p stereo pair (two 1920×1080 RGBA8
// views: a textured plane 48 px in front of a textured background 16 px behind the screen), both
// views' maps, against its natural peer: OpenCV's semi-global matcher (StereoSGBM, 3-way) on the
// same pair at the same working resolution (480×270) and range, one view only. Then a plane close
// to the eye (a third of the width in front), where the range probe lowers the working width.
// usage: nelf_stereo_matcher_bench [RUNS] [THREADS]
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench/bench_timing.hpp"
#include "inputs/stereo_matcher.hpp"

namespace {

float texture(int u, int v, unsigned seed) {
  const auto lattice = [seed](int i, int j) {
    std::uint32_t h = static_cast<std::uint32_t>(i) * 73856093u ^ static_cast<std::uint32_t>(j) * 19349663u ^ seed;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return static_cast<float>(h & 0xffffu) / 65535.f;
  };
  const auto octave = [&](int cell) {
    const int i = static_cast<int>(std::floor(static_cast<float>(u) / static_cast<float>(cell)));
    const int j = static_cast<int>(std::floor(static_cast<float>(v) / static_cast<float>(cell)));
    const float fx = static_cast<float>(u - i * cell) / static_cast<float>(cell);
    const float fy = static_cast<float>(v - j * cell) / static_cast<float>(cell);
    const float top = lattice(i, j) * (1 - fx) + lattice(i + 1, j) * fx;
    const float bottom = lattice(i, j + 1) * (1 - fx) + lattice(i + 1, j + 1) * fx;
    return top * (1 - fy) + bottom * fy;
  };
  return 0.6f * octave(12) + 0.4f * octave(4);
}

nelf::StereoVideoFrame pair(int width, int height, int background_d, int plane_d) {
  nelf::StereoVideoFrame f;
  f.width = width;
  f.height = height;
  f.left.resize(static_cast<std::size_t>(width) * height * 4);
  f.right.resize(f.left.size());
  const auto on_plane = [&](int x, int y) {
    return x >= width / 3 && x < width * 2 / 3 && y >= height / 4 && y < height * 3 / 4;
  };
  const auto put = [](std::vector<std::uint8_t>& view, std::size_t i, float value) {
    const auto v = static_cast<std::uint8_t>(std::lround(value * 255.f));
    view[i * 4] = view[i * 4 + 1] = v;
    view[i * 4 + 2] = static_cast<std::uint8_t>(v / 2 + 64);
    view[i * 4 + 3] = 255;
  };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      put(f.left, i, on_plane(x, y) ? texture(x - width / 3, y, 8) : texture(x, y, 7));
      put(f.right, i,
          on_plane(x + plane_d, y) ? texture(x + plane_d - width / 3, y, 8) : texture(x + background_d, y, 7));
    }
  return f;
}

cv::Mat working_gray(const std::vector<std::uint8_t>& view, int width, int height) {
  cv::Mat rgba(height, width, CV_8UC4, const_cast<std::uint8_t*>(view.data())), gray, small;
  cv::cvtColor(rgba, gray, cv::COLOR_RGBA2GRAY);
  cv::resize(gray, small, cv::Size(480, 270), 0, 0, cv::INTER_AREA);
  return small;
}

// `video`: each run is the next frame of one shot (the range tracked from the last estimate, the
// probe every 12th frame); otherwise every run is the cold cost of a first frame.
double time_estimate(const nelf::StereoVideoFrame& frame, int runs, bool video = false) {
  nelf::StereoMatcherSettings settings;
  if (!video) settings.temporal_weight = 0;
  nelf::StereoMatcher matcher(settings);
  std::vector<double> ms;
  for (int i = 0; i <= runs; ++i) {
    const double t = nelf::bench::elapsed_ms([&] {
      if (!matcher.estimate(frame)) std::abort();
    });
    if (i > 0) ms.push_back(t);
  }
  return nelf::bench::median(ms);
}

}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::atoi(argv[1]) : 31;
  const int threads = argc > 2 ? std::atoi(argv[2]) : 0;
  if (threads > 0) cv::setNumThreads(threads);
  const nelf::StereoVideoFrame typical = pair(1920, 1080, -16, 48);
  const nelf::StereoVideoFrame near = pair(1920, 1080, 0, 640);

  nelf::StereoMatcherSettings settings;
  settings.threads = threads;
  const nelf::StereoMatcher set_threads(settings);  // cv::setNumThreads as the estimator sets it
  const double own = time_estimate(typical, runs);
  // The peer: 3-way SGBM over as many disparities as the estimator searches for this pair at 480
  // wide (48, from -16), on grays made by OpenCV itself, the left map only.
  auto sgbm = cv::StereoSGBM::create(-16, 48, 5, 8 * 25, 32 * 25, 1, 0, 10, 50, 2, cv::StereoSGBM::MODE_SGBM_3WAY);
  std::vector<double> peer;
  for (int i = 0; i <= runs; ++i) {
    const double t = nelf::bench::elapsed_ms([&] {
      cv::Mat d;
      sgbm->compute(working_gray(typical.left, 1920, 1080), working_gray(typical.right, 1920, 1080), d);
    });
    if (i > 0) peer.push_back(t);
  }
  const double sgbm_ms = nelf::bench::median(peer);
  const double near_ms = time_estimate(near, runs);
  std::printf("disparity of a 1920x1080 RGBA8 stereo pair, median of %d runs, %d OpenCV threads\n", runs,
              cv::getNumThreads());
  std::printf("nelf estimate, both views (480x270 working, maps 960x540)   %7.2f ms\n", own);
  std::printf("OpenCV StereoSGBM 3-way, left view only, same size/range    %7.2f ms\n", sgbm_ms);
  std::printf("ratio                                                       %7.2f (SGBM / nelf)\n", sgbm_ms / own);
  std::printf("nelf estimate, plane a third of the width in front          %7.2f ms\n", near_ms);
  std::printf("nelf estimate, the 1080p pair as the next frame of a shot     %7.2f ms\n",
              time_estimate(typical, runs, true));
}
