#include "support/gl_test_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "support/test_support.hpp"

namespace nelf::test {

std::shared_ptr<gl::EglContext> shared_gl_context() {
  static TempDir shader_cache;
  static std::shared_ptr<gl::EglContext> context = [] {
    setenv("MESA_SHADER_CACHE_DIR", shader_cache.path().c_str(), 1);
    setenv("LP_NUM_THREADS", "2", 0);
    return std::make_shared<gl::EglContext>();
  }();
  return context;
}

Image photo_chart(int width, int height) {
  Image image(width, height);
  const double pi = std::numbers::pi;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double u = (x + 0.5) / width, t = (y + 0.5) / height;
      // Smooth "sky and ground" gradients.
      double r = 0.25 + 0.5 * u, g = 0.3 + 0.4 * t * (1 - u), b = 0.7 - 0.4 * t;
      // Mid-frequency texture: periods of ~1/40 and ~1/27 of the width (a few pixel footprints).
      const double texture = 0.06 * std::sin(2 * pi * 40 * u) * std::sin(2 * pi * 27 * t * height / width * 16 / 9);
      r += texture, g += texture, b += texture;
      // Hard-edged shapes: a disc, a bar and a rotated square.
      if ((u - 0.3) * (u - 0.3) + (t - 0.4) * (t - 0.4) * 0.3 < 0.01) r = 0.9, g = 0.8, b = 0.2;
      if (u > 0.6 && u < 0.65 && t > 0.2 && t < 0.8) r = g = b = 0.05;
      const double su = (u - 0.75) + (t - 0.6), sv = (u - 0.75) - (t - 0.6);
      if (std::abs(su) < 0.08 && std::abs(sv) < 0.08) r = 0.1, g = 0.6, b = 0.3;
      image.at(x, y) = {static_cast<float>(std::clamp(r, 0.0, 1.0)), static_cast<float>(std::clamp(g, 0.0, 1.0)),
                        static_cast<float>(std::clamp(b, 0.0, 1.0)), 1.f};
    }
  }
  return image;
}

Image zone_plate(int width, int height) {
  Image image(width, height);
  // Phase π r² / (2 R) has local frequency r / (2 R) cycles per texel: Nyquist (½) at r = R.
  const double cx = width / 2.0, cy = height / 2.0, radius = std::hypot(cx, cy);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
      const float v = static_cast<float>(0.5 + 0.5 * std::cos(std::numbers::pi * (dx * dx + dy * dy) / (2 * radius)));
      image.at(x, y) = {v, v, v, 1.f};
    }
  return image;
}

double psnr(const Image& a, const Image& b) {
  if (a.width() != b.width() || a.height() != b.height()) throw std::invalid_argument("psnr: sizes differ");
  double sum = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    const Rgba &p = a.pixels()[i], &q = b.pixels()[i];
    sum += (p.r - q.r) * (p.r - q.r) + (p.g - q.g) * (p.g - q.g) + (p.b - q.b) * (p.b - q.b);
  }
  const double mse = sum / (3.0 * static_cast<double>(a.pixels().size()));
  return mse == 0 ? std::numeric_limits<double>::infinity() : 10 * std::log10(1.0 / mse);
}

double max_abs_difference(const Image& a, const Image& b) {
  if (a.width() != b.width() || a.height() != b.height()) throw std::invalid_argument("max_abs_difference: sizes");
  double worst = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    const Rgba &p = a.pixels()[i], &q = b.pixels()[i];
    worst = std::max({worst, std::abs(static_cast<double>(p.r - q.r)), std::abs(static_cast<double>(p.g - q.g)),
                      std::abs(static_cast<double>(p.b - q.b))});
  }
  return worst;
}

std::shared_ptr<const DisparitySurface> near_block_surface(const Profile& profile, double aspect, int width,
                                                           int height) {
  const EyeMapping m = make_eye_mapping(profile, Eye::left, aspect);
  const DepthGeometry g = depth_geometry(profile, m);
  const float near_px = static_cast<float>(disparity_mm_from_depth(g, 250.0) / g.screen_size_mm.x * width);
  ViewDisparity d{width, height, std::vector<float>(static_cast<std::size_t>(width) * height, 0.f)};
  for (int y = height / 4; y < 3 * height / 4; ++y)
    for (int x = width / 6; x < width / 2; ++x) d.d[static_cast<std::size_t>(y) * width + x] = near_px;
  return std::make_shared<const DisparitySurface>(d);
}

Profile small_panel_profile() {
  return parse_profile(R"(
name = "hmz-t1-small"
[display]
resolution = [320, 180]
pixel_pitch_mm = 0.048
[lens_array]
pitch_mm = 1.0
focal_length_mm = 3.3
[viewing]
eye_relief_mm = 25.0
virtual_image_mm = 1000.0
pupil_mm = 4.0
ipd_mm = 63.0
)",
                       "small-panel test profile");
}

std::vector<std::uint8_t> block_means(const Image& view, std::array<int, 2> block) {
  const int w = view.width() / block[0], h = view.height() / block[1];
  std::vector<std::uint8_t> means(static_cast<std::size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 4; ++c) {
        double sum = 0.0;
        for (int j = 0; j < block[1]; ++j)
          for (int i = 0; i < block[0]; ++i)
            sum += view.data()[(static_cast<std::size_t>(y * block[1] + j) * view.width() + x * block[0] + i) * 4 + c];
        means[(static_cast<std::size_t>(y) * w + x) * 4 + c] =
            static_cast<std::uint8_t>(std::lround(std::clamp(sum / (block[0] * block[1]), 0.0, 1.0) * 255.0));
      }
  return means;
}

}  // namespace nelf::test
