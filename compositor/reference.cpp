#include "compositor/reference.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

namespace nelf {

void validate_fsaa(int fsaa) {
  if (fsaa != 0 && fsaa != 1 && fsaa != 4 && fsaa != 16)
    throw std::invalid_argument(fmt::format("--fsaa must be 0, 1, 4 or 16, got {}", fsaa));
}

const std::vector<std::string>& depth_mode_names() {
  static const std::vector<std::string> names{"off", "auto", "estimate"};
  return names;
}

std::optional<DepthMode> parse_depth_mode(std::string_view name) {
  if (name == "off") return DepthMode::off;
  if (name == "auto") return DepthMode::automatic;
  if (name == "estimate") return DepthMode::estimate;
  return std::nullopt;
}

std::string_view depth_mode_name(DepthMode mode) {
  switch (mode) {
    case DepthMode::off:
      return "off";
    case DepthMode::automatic:
      return "auto";
    case DepthMode::estimate:
      return "estimate";
  }
  return "off";
}

Rgba sample_bilinear(const Image& image, double u, double t) {
  const double x = u * image.width() - 0.5, y = t * image.height() - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double ax = x - fx, ay = y - fy;
  const int x0 = std::clamp(static_cast<int>(fx), 0, image.width() - 1);
  const int x1 = std::clamp(static_cast<int>(fx) + 1, 0, image.width() - 1);
  const int y0 = std::clamp(static_cast<int>(fy), 0, image.height() - 1);
  const int y1 = std::clamp(static_cast<int>(fy) + 1, 0, image.height() - 1);
  const Rgba &p00 = image.at(x0, y0), &p10 = image.at(x1, y0), &p01 = image.at(x0, y1), &p11 = image.at(x1, y1);
  const auto mix = [&](float a, float b, float c, float d) {
    return static_cast<float>((1 - ay) * ((1 - ax) * a + ax * b) + ay * ((1 - ax) * c + ax * d));
  };
  return {mix(p00.r, p10.r, p01.r, p11.r), mix(p00.g, p10.g, p01.g, p11.g), mix(p00.b, p10.b, p01.b, p11.b),
          mix(p00.a, p10.a, p01.a, p11.a)};
}

namespace {

Image render_reference(const EyeMapping& mapping, const Image& view, int subsamples,
                       const std::function<std::optional<Vec2>(Vec2)>& coordinate) {
  if (subsamples < 1) throw std::invalid_argument("reference_eye_image: subsamples must be >= 1");
  if (view.empty()) throw std::invalid_argument("reference_eye_image: empty view");
  Image out(mapping.panel[0], mapping.panel[1]);
  const double inv = 1.0 / subsamples;
  const double weight = inv * inv;
  const auto render_rows = [&](int first, int step) {
    for (int j = first; j < out.height(); j += step) {
      for (int i = 0; i < out.width(); ++i) {
        double r = 0, g = 0, b = 0;
        for (int sy = 0; sy < subsamples; ++sy) {
          for (int sx = 0; sx < subsamples; ++sx) {
            const auto uv = coordinate(display_position_mm(mapping, i + (sx + 0.5) * inv, j + (sy + 0.5) * inv));
            if (!uv) continue;  // black there
            const Rgba c = sample_bilinear(view, uv->x, uv->y);
            r += c.r, g += c.g, b += c.b;
          }
        }
        out.at(i, j) = {static_cast<float>(r * weight), static_cast<float>(g * weight), static_cast<float>(b * weight),
                        1.f};
      }
    }
  };
  const int workers = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::jthread> threads;
  for (int w = 1; w < workers; ++w) threads.emplace_back(render_rows, w, workers);
  render_rows(0, workers);
  return out;
}

}  // namespace

Image reference_eye_image(const EyeMapping& mapping, const Image& view, int subsamples) {
  return render_reference(mapping, view, subsamples, [&](Vec2 s) { return view_coordinate(mapping, s); });
}

Image reference_eye_image(const EyeMapping& mapping, const Image& view, const DisparitySurface& surface,
                          const DepthGeometry& geometry, int subsamples) {
  if (!mapping.has_lens_array) return reference_eye_image(mapping, view, subsamples);
  return render_reference(mapping, view, subsamples, [&](Vec2 s) -> std::optional<Vec2> {
    const auto flat = view_coordinate(mapping, s);
    if (!flat) return std::nullopt;
    const Vec2 c = *owner_lens_centre(mapping, s);
    const Vec2 uv = surface.hit(*flat, pupil_gain(geometry, chief_ray_pupil_crossing(mapping, s, c)));
    if (uv.x < 0.0 || uv.x > 1.0 || uv.y < 0.0 || uv.y > 1.0) return std::nullopt;
    return uv;
  });
}

EyeImages ReferenceCompositor::compose(const StereoPair& views) {
  EyeImages eyes;
  for (Eye eye : {Eye::left, Eye::right}) {
    const View& v = eye == Eye::left ? views.left : views.right;
    const EyeMapping mapping = make_eye_mapping(profile_, eye, v.aspect());
    const auto& surface = surfaces_[static_cast<int>(eye)];
    eyes[static_cast<int>(eye)] =
        surface && profile_.lens_array
            ? reference_eye_image(mapping, v.image, *surface, depth_geometry(profile_, mapping), subsamples_)
            : reference_eye_image(mapping, v.image, subsamples_);
  }
  return eyes;
}

}  // namespace nelf
