#include "inputs/synthetic_source.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <thread>

#include "optics/depth.hpp"
#include "optics/mapping.hpp"

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

double parse_in_range(const std::string& key, const std::string& value, double lo, double hi, const char* unit) {
  const double v = parse_number(key, value);
  if (!(v >= lo && v <= hi))
    throw std::invalid_argument(fmt::format("synthetic: {} must be in [{}, {}] {}, got {}", key, lo, hi, unit, value));
  return v;
}

// Runs rows(first, step) on every core: row j belongs to worker j % workers.
template <class Rows>
void on_all_cores(const Rows& rows) {
  const int workers = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<std::jthread> threads;
  for (int k = 1; k < workers; ++k) threads.emplace_back(rows, k, workers);
  rows(0, workers);
}

// A value noise in [0, 1] on a lattice of unit cells, smoothly interpolated: the planes' texture,
// dense enough everywhere for focus to show and for a stereo matcher to find.
double lattice_value(long x, long y, int salt) {
  std::uint32_t h = static_cast<std::uint32_t>(x) * 0x8da6b343u ^ static_cast<std::uint32_t>(y) * 0xd8163841u ^
                    static_cast<std::uint32_t>(salt) * 0xcb1ab31fu;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return (h & 0xffffu) / 65535.0;
}

double value_noise(double x, double y, int salt) {
  const double fx = std::floor(x), fy = std::floor(y);
  const long ix = static_cast<long>(fx), iy = static_cast<long>(fy);
  const double tx = x - fx, ty = y - fy;
  const double sx = tx * tx * (3 - 2 * tx), sy = ty * ty * (3 - 2 * ty);
  const double top = lattice_value(ix, iy, salt) * (1 - sx) + lattice_value(ix + 1, iy, salt) * sx;
  const double bottom = lattice_value(ix, iy + 1, salt) * (1 - sx) + lattice_value(ix + 1, iy + 1, salt) * sx;
  return top * (1 - sy) + bottom * sy;
}

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
      throw std::invalid_argument(fmt::format(
          "synthetic: option '{}' must be key=value (duration, fps, size, scene, near, far, screen, ipd, fov)", item));
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
    } else if (key == "scene") {
      if (value == "spheres")
        s.scene = SyntheticScene::spheres;
      else if (value == "planes")
        s.scene = SyntheticScene::planes;
      else
        throw std::invalid_argument(fmt::format("synthetic: scene must be spheres or planes, got '{}'", value));
    } else if (key == "near") {
      s.near_mm = parse_in_range(key, value, 50, 100000, "mm");
    } else if (key == "far") {
      s.far_mm = parse_in_range(key, value, 50, 100000, "mm");
    } else if (key == "screen") {
      s.screen_distance_mm = parse_in_range(key, value, 50, 100000, "mm");
      s.camera_given = true;
    } else if (key == "ipd") {
      s.ipd_mm = parse_in_range(key, value, 1, 200, "mm");
      s.camera_given = true;
    } else if (key == "fov") {
      s.horizontal_fov_deg = parse_in_range(key, value, 1, 170, "degrees");
      s.camera_given = true;
    } else {
      throw std::invalid_argument(
          fmt::format("synthetic: unknown option '{}' (duration, fps, size, scene, near, far, screen, ipd, fov)", key));
    }
  }
  if (!(s.near_mm < s.far_mm))
    throw std::invalid_argument(
        fmt::format("synthetic: the near plane ({} mm) must be nearer than the far one ({} mm)", s.near_mm, s.far_mm));
  return s;
}

SyntheticClipSettings matched_to_display(SyntheticClipSettings settings, const Profile& display) {
  if (settings.camera_given || !display.lens_array) return settings;
  const double aspect = static_cast<double>(settings.eye_width) / settings.eye_height;
  const DepthGeometry g = depth_geometry(display, make_eye_mapping(display, Eye::left, aspect));
  settings.screen_distance_mm = g.screen_distance_mm;
  settings.horizontal_fov_deg = 360.0 / std::numbers::pi * std::atan(g.screen_size_mm.x / 2 / g.screen_distance_mm);
  settings.ipd_mm = g.ipd_mm;
  return settings;
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
  if (settings_.scene == SyntheticScene::planes) {
    // A still scene: rendered once, 4 × 4 samples a pixel so the texture is antialiased like film.
    const double aspect = static_cast<double>(settings_.eye_width) / settings_.eye_height;
    planes_pair_.left = View{render_eye(-settings_.ipd_mm / 2, 0, 4), aspect};
    planes_pair_.right = View{render_eye(settings_.ipd_mm / 2, 0, 4), aspect};
  }
}

int SyntheticClip::frame_count() const {
  return std::max(1, static_cast<int>(std::lround(settings_.duration_s * settings_.fps)));
}

StereoPair SyntheticClip::render(int index) const {
  if (index < 0 || index >= frame_count()) throw std::out_of_range("SyntheticClip::render: frame index");
  if (settings_.scene == SyntheticScene::planes) return planes_pair_;
  const double t = static_cast<double>(index) / settings_.fps;
  StereoPair pair;
  const double aspect = static_cast<double>(settings_.eye_width) / settings_.eye_height;
  pair.left = View{render_eye(-settings_.ipd_mm / 2, t, 1), aspect};
  pair.right = View{render_eye(settings_.ipd_mm / 2, t, 1), aspect};
  return pair;
}

double SyntheticClip::screen_width_mm() const {
  return 2 * settings_.screen_distance_mm * std::tan(settings_.horizontal_fov_deg * std::numbers::pi / 360.0);
}

Vec2 SyntheticClip::screen_point_mm(double x, double y) const {
  // Off-axis stereo camera: each eye looks through the same screen rectangle at z = D, so objects at
  // the screen distance have zero parallax. (x, y) in view pixels, (0, 0) the top-left corner.
  const double screen_w = screen_width_mm(), screen_h = screen_w * settings_.eye_height / settings_.eye_width;
  return {(x / settings_.eye_width - 0.5) * screen_w, (0.5 - y / settings_.eye_height) * screen_h};
}

std::vector<SyntheticClip::Sphere> SyntheticClip::spheres_at(double t) const {
  std::vector<Sphere> now = spheres_;
  for (auto& s : now) {
    s.x += s.swing_x * std::sin(2 * std::numbers::pi * 0.25 * t + s.phase);
    s.z += s.swing_z * std::sin(2 * std::numbers::pi * 0.2 * t + s.phase);
  }
  return now;
}

SyntheticClip::Surface SyntheticClip::surface(const std::vector<Sphere>& now, double eye_x_mm, Vec2 screen) const {
  const double d = settings_.screen_distance_mm;
  double dir[3] = {screen.x - eye_x_mm, screen.y, d};
  const double len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  for (double& c : dir) c /= len;
  if (settings_.scene == SyntheticScene::planes) {
    // The near plane is a rectangle centred ahead, a third of the view wide and half of it high at
    // its depth; the far plane fills the rest. Both textured at the same angular scale (three view
    // pixels a cell, and a coarser octave), so that each shows focus equally.
    const double tan_half = screen_width_mm() / (2 * d);
    const double cell_per_mm = settings_.eye_width / (3.0 * 2 * tan_half);  // cells per mm at 1 mm depth
    const auto plane = [&](double z, int salt, Rgba tint) {
      const double x = eye_x_mm + dir[0] * z / dir[2], y = dir[1] * z / dir[2];
      const double u = x * cell_per_mm / z, v = y * cell_per_mm / z;
      const float k =
          static_cast<float>(0.1 + 0.55 * value_noise(u, v, salt) + 0.3 * value_noise(u / 4, v / 4, salt + 1));
      return Surface{{tint.r * k, tint.g * k, tint.b * k, 1}, z};
    };
    const double z = settings_.near_mm;
    const double x = eye_x_mm + dir[0] * z / dir[2], y = dir[1] * z / dir[2];
    const double half_w = z * tan_half / 3, half_h = z * tan_half * settings_.eye_height / settings_.eye_width / 2;
    if (std::abs(x) <= half_w && std::abs(y) <= half_h) return plane(z, 11, {1.0f, 0.62f, 0.35f, 1});
    return plane(settings_.far_mm, 23, {0.4f, 0.7f, 1.0f, 1});
  }
  // Wall: a checkerboard with 200 mm squares, shaded by a horizontal gradient.
  const double wall_z = 3.0 * d;
  const double tw = wall_z / dir[2];
  const double wx = eye_x_mm + dir[0] * tw, wy = dir[1] * tw;
  const bool odd = (static_cast<long>(std::floor(wx / 200.0)) + static_cast<long>(std::floor(wy / 200.0))) & 1;
  const float shade = static_cast<float>(0.55 + 0.2 * std::sin(wx / 900.0));
  Surface front{odd ? Rgba{0.85f * shade, 0.85f * shade, 0.8f * shade, 1} : Rgba{0.2f, 0.22f, 0.3f, 1}, wall_z};
  double nearest = tw;
  const double light[3] = {-0.4, 0.6, -0.7};
  const double light_norm = std::sqrt(light[0] * light[0] + light[1] * light[1] + light[2] * light[2]);
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
    front = {{s.colour.r * k, s.colour.g * k, s.colour.b * k, 1}, hit * dir[2]};
  }
  return front;
}

Image SyntheticClip::render_eye(double eye_x_mm, double t, int samples) const {
  const int w = settings_.eye_width, h = settings_.eye_height;
  const std::vector<Sphere> now = spheres_at(t);
  Image img(w, h);
  on_all_cores([&](int first, int step) {
    for (int j = first; j < h; j += step)
      for (int i = 0; i < w; ++i) {
        // samples × samples points per pixel, box-filtered (1: the pixel centre).
        Rgba sum{0, 0, 0, 0};
        for (int sy = 0; sy < samples; ++sy)
          for (int sx = 0; sx < samples; ++sx) {
            const Rgba c =
                surface(now, eye_x_mm, screen_point_mm(i + (sx + 0.5) / samples, j + (sy + 0.5) / samples)).colour;
            sum = {sum.r + c.r, sum.g + c.g, sum.b + c.b, 1};
          }
        const float n = static_cast<float>(samples * samples);
        img.at(i, j) = {sum.r / n, sum.g / n, sum.b / n, 1};
      }
  });
  return img;
}

std::vector<double> SyntheticClip::depth_mm(double eye_x_mm, double t) const {
  const int w = settings_.eye_width, h = settings_.eye_height;
  const std::vector<Sphere> now = spheres_at(t);
  std::vector<double> z(static_cast<std::size_t>(w) * h);
  on_all_cores([&](int first, int step) {
    for (int j = first; j < h; j += step)
      for (int i = 0; i < w; ++i)
        z[static_cast<std::size_t>(j) * w + i] = surface(now, eye_x_mm, screen_point_mm(i + 0.5, j + 0.5)).z;
  });
  return z;
}

std::shared_ptr<const StereoDisparity> SyntheticClip::disparity(int index) const {
  if (index < 0 || index >= frame_count()) throw std::out_of_range("SyntheticClip::disparity: frame index");
  const double t = static_cast<double>(index) / settings_.fps;
  // δ = e (D/Z − 1) mm on the screen (optics/depth.hpp), in view pixels.
  const double px_per_mm = settings_.eye_width / screen_width_mm();
  const auto view = [&](double eye_x_mm) {
    ViewDisparity v{settings_.eye_width, settings_.eye_height, {}};
    for (double z : depth_mm(eye_x_mm, t))
      v.d.push_back(static_cast<float>(settings_.ipd_mm * (settings_.screen_distance_mm / z - 1) * px_per_mm));
    return v;
  };
  auto both = std::make_shared<StereoDisparity>();
  both->left = view(-settings_.ipd_mm / 2);
  both->right = view(settings_.ipd_mm / 2);
  both->origin = DisparityOrigin::known;
  return both;
}

std::vector<SceneRegion> SyntheticClip::regions(int index) const {
  if (index < 0 || index >= frame_count()) throw std::out_of_range("SyntheticClip::regions: frame index");
  if (settings_.scene != SyntheticScene::planes) return {};
  std::vector<SceneRegion> out{{"near", settings_.near_mm, {}, {}}, {"far", settings_.far_mm, {}, {}}};
  const auto mark = [&](double eye_x_mm, auto member) {
    for (double z : depth_mm(eye_x_mm, 0))
      for (SceneRegion& r : out) (r.*member).push_back(z == r.depth_mm ? 1 : 0);
  };
  mark(-settings_.ipd_mm / 2, &SceneRegion::left_mask);
  mark(settings_.ipd_mm / 2, &SceneRegion::right_mask);
  return out;
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
