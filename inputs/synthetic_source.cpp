#include "inputs/synthetic_source.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <thread>

namespace nelf {

namespace {

constexpr std::string_view prefix = "synthetic:";

double parse_number(const std::string& key, const std::string& value) {
  try {
    std::size_t used = 0;
    const double v = std::stod(value, &used);
    if (used == value.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument(fmt::format("synthetic: option {} needs a number, got '{}'", key, value));
}

// A uniform number in [lo, hi) from the generator's raw output (portable, unlike std distributions).
double uniform(std::mt19937& rng, double lo, double hi) { return lo + (hi - lo) * (rng() / 4294967296.0); }

}  // namespace

bool is_synthetic_spec(const std::string& input) { return input.rfind(prefix, 0) == 0; }

SyntheticClipSettings parse_synthetic_spec(const std::string& spec) {
  if (!is_synthetic_spec(spec)) throw std::invalid_argument(fmt::format("not a synthetic source: {}", spec));
  SyntheticClipSettings s;
  std::string rest = spec.substr(prefix.size());
  while (!rest.empty()) {
    const auto comma = rest.find(',');
    const std::string item = rest.substr(0, comma);
    rest = comma == std::string::npos ? "" : rest.substr(comma + 1);
    const auto eq = item.find('=');
    if (eq == std::string::npos)
      throw std::invalid_argument(fmt::format("synthetic: option '{}' must be key=value (duration, fps, size)", item));
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "duration") {
      s.duration_s = parse_number(key, value);
      if (!(s.duration_s > 0 && s.duration_s <= 3600))
        throw std::invalid_argument(fmt::format("synthetic: duration must be in (0, 3600] s, got {}", value));
    } else if (key == "fps") {
      const double fps = parse_number(key, value);
      if (fps < 1 || fps > 240 || fps != std::floor(fps))
        throw std::invalid_argument(fmt::format("synthetic: fps must be a whole number 1..240, got {}", value));
      s.fps = static_cast<int>(fps);
    } else if (key == "size") {
      const auto x = value.find('x');
      if (x == std::string::npos)
        throw std::invalid_argument(fmt::format("synthetic: size must be WxH, got '{}'", value));
      const double w = parse_number(key, value.substr(0, x)), h = parse_number(key, value.substr(x + 1));
      if (w < 16 || h < 16 || w > 4096 || h > 4096 || w != std::floor(w) || h != std::floor(h))
        throw std::invalid_argument(
            fmt::format("synthetic: size must be whole pixels 16..4096 per side, got '{}'", value));
      s.eye_width = static_cast<int>(w);
      s.eye_height = static_cast<int>(h);
    } else {
      throw std::invalid_argument(fmt::format("synthetic: unknown option '{}' (duration, fps, size)", key));
    }
  }
  return s;
}

SyntheticClip::SyntheticClip(SyntheticClipSettings settings) : settings_(settings) {
  std::mt19937 rng(20131101);  // fixed seed: the same clip on every machine
  const double d = settings_.screen_distance_mm;
  // Depths from well in front of the screen to well behind it (fractions of the screen distance).
  const double depths[] = {0.55, 0.75, 1.0, 1.4, 2.0};
  const Rgba palette[] = {{0.95f, 0.35f, 0.2f, 1},
                          {0.2f, 0.75f, 0.35f, 1},
                          {0.95f, 0.85f, 0.2f, 1},
                          {0.3f, 0.5f, 0.95f, 1},
                          {0.8f, 0.35f, 0.85f, 1}};
  for (int i = 0; i < 5; ++i) {
    Sphere s;
    s.z = depths[i] * d;
    const double half_width = s.z * std::tan(settings_.horizontal_fov_deg * std::numbers::pi / 360.0);
    // Spread across the view (one sphere per fifth of the width), jittered by the seed.
    const double screen_half_width = d * std::tan(settings_.horizontal_fov_deg * std::numbers::pi / 360.0);
    s.x = ((i - 2) * 0.32 + uniform(rng, -0.05, 0.05)) * screen_half_width * depths[i];
    s.y = uniform(rng, -0.3, 0.3) * screen_half_width * depths[i] * 0.5;
    s.radius = 0.09 * half_width;
    s.swing_x = uniform(rng, 0.05, 0.12) * half_width;
    s.swing_z = uniform(rng, 0.0, 0.1) * d;
    s.phase = uniform(rng, 0, 2 * std::numbers::pi);
    s.colour = palette[i];
    spheres_.push_back(s);
  }
}

int SyntheticClip::frame_count() const {
  return std::max(1, static_cast<int>(std::lround(settings_.duration_s * settings_.fps)));
}

StereoPair SyntheticClip::render(int index) const {
  if (index < 0 || index >= frame_count()) throw std::out_of_range("SyntheticClip::render: frame index");
  const double t = static_cast<double>(index) / settings_.fps;
  StereoPair pair;
  const double aspect = static_cast<double>(settings_.eye_width) / settings_.eye_height;
  pair.left = View{render_eye(-settings_.ipd_mm / 2, t), aspect};
  pair.right = View{render_eye(settings_.ipd_mm / 2, t), aspect};
  return pair;
}

Image SyntheticClip::render_eye(double eye_x_mm, double t) const {
  const int w = settings_.eye_width, h = settings_.eye_height;
  const double d = settings_.screen_distance_mm;
  const double screen_w = 2 * d * std::tan(settings_.horizontal_fov_deg * std::numbers::pi / 360.0);
  const double screen_h = screen_w * h / w;
  const double wall_z = 3.0 * d;
  // Sphere positions at time t.
  std::vector<Sphere> now = spheres_;
  for (auto& s : now) {
    s.x += s.swing_x * std::sin(2 * std::numbers::pi * 0.25 * t + s.phase);
    s.z += s.swing_z * std::sin(2 * std::numbers::pi * 0.2 * t + s.phase);
  }
  const double light[3] = {-0.4, 0.6, -0.7};
  const double light_norm = std::sqrt(light[0] * light[0] + light[1] * light[1] + light[2] * light[2]);
  Image img(w, h);
  const auto render_rows = [&](int first, int step) {
    for (int j = first; j < h; j += step) {
      for (int i = 0; i < w; ++i) {
        // Off-axis stereo camera: each eye looks through the same screen rectangle at z = d, so objects
        // at the screen distance have zero parallax.
        const double px = ((i + 0.5) / w - 0.5) * screen_w, py = (0.5 - (j + 0.5) / h) * screen_h;
        double dir[3] = {px - eye_x_mm, py, d};
        const double len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        for (double& c : dir) c /= len;
        // Wall: a checkerboard with 200 mm squares, shaded by a horizontal gradient.
        const double tw = wall_z / dir[2];
        const double wx = eye_x_mm + dir[0] * tw, wy = dir[1] * tw;
        const bool odd = (static_cast<long>(std::floor(wx / 200.0)) + static_cast<long>(std::floor(wy / 200.0))) & 1;
        const float shade = static_cast<float>(0.55 + 0.2 * std::sin(wx / 900.0));
        Rgba colour = odd ? Rgba{0.85f * shade, 0.85f * shade, 0.8f * shade, 1} : Rgba{0.2f, 0.22f, 0.3f, 1};
        double nearest = tw;
        for (const auto& s : now) {
          const double oc[3] = {eye_x_mm - s.x, -s.y, -s.z};
          const double b = oc[0] * dir[0] + oc[1] * dir[1] + oc[2] * dir[2];
          const double c = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - s.radius * s.radius;
          const double disc = b * b - c;
          if (disc < 0) continue;
          const double hit = -b - std::sqrt(disc);
          if (hit <= 0 || hit >= nearest) continue;
          nearest = hit;
          const double n[3] = {(oc[0] + dir[0] * hit) / s.radius, (oc[1] + dir[1] * hit) / s.radius,
                               (oc[2] + dir[2] * hit) / s.radius};
          const double lambert = std::max(0.0, (n[0] * light[0] + n[1] * light[1] + n[2] * light[2]) / light_norm);
          // Latitude stripes give each sphere texture to fuse on.
          const float stripe = std::sin(std::asin(std::clamp(n[1], -1.0, 1.0)) * 12.0) > 0 ? 1.0f : 0.75f;
          const float k = static_cast<float>(0.25 + 0.75 * lambert) * stripe;
          colour = {s.colour.r * k, s.colour.g * k, s.colour.b * k, 1};
        }
        img.at(i, j) = colour;
      }
    }
  };
  const int workers = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<std::jthread> threads;
  for (int k = 1; k < workers; ++k) threads.emplace_back(render_rows, k, workers);
  render_rows(0, workers);
  return img;
}

std::vector<float> SyntheticClip::audio(std::int64_t first, int count) const {
  std::vector<float> samples(static_cast<std::size_t>(std::max(0, count)));
  for (int k = 0; k < count; ++k) {
    const double time = static_cast<double>(first + k) / settings_.audio_rate;
    // A 440 Hz tone with a soft 2 Hz pulse, so it is audibly alive but never clips.
    samples[static_cast<std::size_t>(k)] =
        static_cast<float>(0.3 * std::sin(2 * std::numbers::pi * 440.0 * time) *
                           (0.75 + 0.25 * std::cos(2 * std::numbers::pi * 2.0 * time)));
  }
  return samples;
}

}  // namespace nelf
