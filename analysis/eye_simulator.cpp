#include "analysis/eye_simulator.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "compositor/reference.hpp"

namespace nelf {

namespace {

constexpr double degrees_per_radian = 180.0 / std::numbers::pi;

// Runs render_row(j) for every row, rows interleaved over the available cores.
template <typename RowFunction>
void for_each_row(int rows, const RowFunction& render_row) {
  const int workers = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const auto worker = [&](int first) {
    for (int j = first; j < rows; j += workers) render_row(j);
  };
  std::vector<std::jthread> threads;
  for (int w = 1; w < workers; ++w) threads.emplace_back(worker, w);
  worker(0);
}

// Bilinear sample at continuous pixel coordinates (x, y) (texel centres at i + ½), texels outside the
// image black: light from beyond the panel's edge does not exist.
Rgba sample_bilinear_black_outside(const Image& image, double x, double y) {
  const double fx = std::floor(x - 0.5), fy = std::floor(y - 0.5);
  const double ax = x - 0.5 - fx, ay = y - 0.5 - fy;
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  Rgba out{0.f, 0.f, 0.f, 1.f};
  const auto add = [&](int xi, int yi, double weight) {
    if (xi < 0 || yi < 0 || xi >= image.width() || yi >= image.height() || weight == 0.0) return;
    const Rgba& p = image.at(xi, yi);
    out.r += static_cast<float>(weight * p.r);
    out.g += static_cast<float>(weight * p.g);
    out.b += static_cast<float>(weight * p.b);
  };
  add(x0, y0, (1 - ax) * (1 - ay));
  add(x0 + 1, y0, ax * (1 - ay));
  add(x0, y0 + 1, (1 - ax) * ay);
  add(x0 + 1, y0 + 1, ax * ay);
  return out;
}

// One axis of the box prefilter: out[i] = mean of the piecewise-constant signal `in` (zero outside
// [0, n)) over [i + ½ − w/2, i + ½ + w/2]. `stride` steps between consecutive elements.
void box_filter_line(const float* in, float* out, int n, std::ptrdiff_t stride, double width,
                     std::vector<double>& prefix) {
  prefix.assign(static_cast<std::size_t>(n) + 1, 0.0);
  for (int k = 0; k < n; ++k) prefix[k + 1] = prefix[k] + in[k * stride];
  const auto integral_to = [&](double x) {  // ∫_0^x of the signal
    if (x <= 0.0) return 0.0;
    if (x >= n) return prefix[n];
    const int k = static_cast<int>(x);
    return prefix[k] + (x - k) * in[k * stride];
  };
  for (int i = 0; i < n; ++i) {
    const double centre = i + 0.5;
    out[i * stride] = static_cast<float>((integral_to(centre + width / 2) - integral_to(centre - width / 2)) / width);
  }
}

}  // namespace

DeviceOptics device_optics(const Profile& profile, Eye eye) {
  if (!profile.lens_array)
    throw ProfileError(
        fmt::format("{}: profile '{}' has no [lens_array]: the eye simulator models light field "
                    "displays only",
                    profile.source, profile.name));
  // The nominal hardware: the same derivation as the rendering, without this eye's calibration.
  Profile nominal = profile;
  nominal.calibration[static_cast<int>(eye)] = EyeCalibration{};
  nominal.screen.width_mm = 1.0;  // the lattice does not depend on the screen; avoid its fitting rules
  const EyeMapping m = make_eye_mapping(nominal, eye, 1.0);
  DeviceOptics d;
  d.panel = m.panel;
  d.pixel_pitch_mm = m.pixel_pitch_mm;
  d.eye_relief_mm = m.eye_relief_mm;
  d.gap_mm = m.gap_mm;
  d.focal_mm = profile.lens_array->focal_length_mm;
  d.lens_pitch_mm = m.lens_pitch_mm;
  d.lattice_offset_mm = m.lattice_offset_mm;
  d.rotation_rad = m.rotation_rad;
  d.first_lens = m.first_lens;
  d.lenses = m.lenses;
  return d;
}

void validate_eye_model(const EyeModel& eye) {
  if (!(eye.pupil_mm > 0.0) || !std::isfinite(eye.pupil_mm))
    throw std::invalid_argument(fmt::format("pupil diameter must be > 0 mm, got {}", eye.pupil_mm));
  if (!(eye.focus_mm > 0.0))
    throw std::invalid_argument(fmt::format("focus distance must be > 0 mm (inf = relaxed), got {}", eye.focus_mm));
  if (!std::isfinite(eye.offset_mm.x) || !std::isfinite(eye.offset_mm.y))
    throw std::invalid_argument("eye offset must be finite");
  if (eye.pupil_samples_per_axis < 1 || eye.pupil_samples_per_axis > 64)
    throw std::invalid_argument(
        fmt::format("pupil samples per axis must be 1..64, got {}", eye.pupil_samples_per_axis));
}

std::vector<Vec2> pupil_samples(double diameter_mm, int per_axis) {
  std::vector<Vec2> points;
  points.reserve(static_cast<std::size_t>(per_axis) * static_cast<std::size_t>(per_axis));
  const double radius = diameter_mm / 2.0;
  for (int j = 0; j < per_axis; ++j) {
    for (int i = 0; i < per_axis; ++i) {
      const double a = 2.0 * (i + 0.5) / per_axis - 1.0, b = 2.0 * (j + 0.5) / per_axis - 1.0;
      double r = 0, phi = 0;
      if (a == 0.0 && b == 0.0) {
        r = 0;
      } else if (std::abs(a) > std::abs(b)) {
        r = a, phi = std::numbers::pi / 4 * (b / a);
      } else {
        r = b, phi = std::numbers::pi / 2 - std::numbers::pi / 4 * (a / b);
      }
      points.push_back({radius * r * std::cos(phi), radius * r * std::sin(phi)});
    }
  }
  return points;
}

Image box_prefilter(const Image& view, Vec2 box_uv) {
  const double width_x = box_uv.x * view.width(), width_y = box_uv.y * view.height();
  if (!(width_x > 0.0) || !(width_y > 0.0)) throw std::invalid_argument("box_prefilter: box must be > 0");
  Image horizontal(view.width(), view.height()), out(view.width(), view.height());
  const std::ptrdiff_t pixel = 4;  // floats per Rgba
  const std::ptrdiff_t row = pixel * view.width();
  for_each_row(view.height(), [&](int j) {
    std::vector<double> prefix;
    for (int channel = 0; channel < 3; ++channel)
      box_filter_line(view.data() + j * row + channel, horizontal.data() + j * row + channel, view.width(), pixel,
                      width_x, prefix);
  });
  for_each_row(view.width(), [&](int i) {  // columns, one per "row" task
    std::vector<double> prefix;
    for (int channel = 0; channel < 3; ++channel)
      box_filter_line(horizontal.data() + i * pixel + channel, out.data() + i * pixel + channel, view.height(), row,
                      width_y, prefix);
  });
  return out;
}

VisualField visual_field_for_screen(const EyeMapping& rendering, const SimulatorOptions& options) {
  if (!rendering.has_lens_array) throw std::invalid_argument("eye simulator: the rendering has no lens array");
  if (!(options.samples_per_footprint > 0.0) || !(options.margin >= 0.0))
    throw std::invalid_argument("eye simulator: samples_per_footprint must be > 0 and margin >= 0");
  const double d_r = rendering.render_distance_mm;
  const Vec2 c = rendering.screen_centre_mm, size = rendering.screen_size_mm;
  double left = std::atan((c.x - size.x / 2) / d_r), right = std::atan((c.x + size.x / 2) / d_r);
  double bottom = std::atan((c.y - size.y / 2) / d_r), top = std::atan((c.y + size.y / 2) / d_r);
  const double margin_x = (right - left) * options.margin, margin_y = (top - bottom) * options.margin;
  left -= margin_x, right += margin_x, bottom -= margin_y, top += margin_y;
  // One display pixel covers p (d_r − d_e)/d_l of the screen (DESIGN.md §4); seen from the eye that is
  // this angle. The finer of the two axes sets the (square) retinal sampling.
  const double k = (d_r - rendering.eye_relief_mm) / rendering.gap_mm;
  const double footprint_rad = std::atan(std::min(rendering.pixel_pitch_mm.x, rendering.pixel_pitch_mm.y) * k / d_r);
  VisualField f;
  f.step_deg = footprint_rad / options.samples_per_footprint * degrees_per_radian;
  f.left_deg = left * degrees_per_radian;
  f.top_deg = top * degrees_per_radian;
  // Checked as doubles: an absurd geometry must not reach the int conversion (NaN or beyond int).
  const double width = std::ceil((right - left) * degrees_per_radian / f.step_deg);
  const double height = std::ceil((top - bottom) * degrees_per_radian / f.step_deg);
  constexpr int max_side = 4096;
  if (!(width >= 1 && height >= 1 && width <= max_side && height <= max_side))
    throw std::invalid_argument(
        fmt::format("eye simulator: retinal image of {}x{} pixels is out of range (1..{})", width, height, max_side));
  f.width = static_cast<int>(width);
  f.height = static_cast<int>(height);
  return f;
}

EyeSimulator::EyeSimulator(DeviceOptics device, const EyeMapping& rendering, const Image& view,
                           SimulatorOptions options)
    : device_(device),
      render_distance_mm_(rendering.render_distance_mm),
      screen_centre_mm_(rendering.screen_centre_mm),
      screen_size_mm_(rendering.screen_size_mm),
      field_(visual_field_for_screen(rendering, options)) {
  if (view.empty()) throw std::invalid_argument("eye simulator: empty view");
  view_width_ = view.width();
  view_height_ = view.height();
  if (!(device_.lens_pitch_mm > 0.0) || !(device_.focal_mm > 0.0) || !(device_.gap_mm > 0.0) ||
      !(device_.eye_relief_mm > 0.0))
    throw std::invalid_argument("eye simulator: device optics need positive pitch, focal length, gap, eye relief");
  band_limited_view_ = box_prefilter(view, pixel_footprint_uv(rendering));
  tan_x_.resize(static_cast<std::size_t>(field_.width));
  tan_y_.resize(static_cast<std::size_t>(field_.height));
  for (int i = 0; i < field_.width; ++i)
    tan_x_[i] = std::tan((field_.left_deg + (i + 0.5) * field_.step_deg) / degrees_per_radian);
  for (int j = 0; j < field_.height; ++j)
    tan_y_[j] = std::tan((field_.top_deg - (j + 0.5) * field_.step_deg) / degrees_per_radian);
}

// Both images share the ray set: from each pupil point P (offset + sample ρ) towards the in-focus point
// F = offset + d_a (tan θx, tan θy), i.e. slope (tan θ) − ρ/d_a (ρ/∞ = 0 for the relaxed eye).

// What one retinal pixel (i, j) collects over the pupil: the per-call constants of retina(), once.
struct EyeSimulator::RetinaTrace {
  const EyeSimulator& sim;
  const Image& displayed;
  const EyeModel& eye;
  std::vector<Vec2> pupil;
  double inv_focus, d_e, d_l, pitch, inv_f, cos_t, sin_t, half_w, half_h, weight;
  Vec2 o;

  RetinaTrace(const EyeSimulator& s, const Image& image, const EyeModel& e)
      : sim(s), displayed(image), eye(e), pupil(pupil_samples(e.pupil_mm, e.pupil_samples_per_axis)) {
    const DeviceOptics& device = sim.device_;
    inv_focus = 1.0 / eye.focus_mm;
    d_e = device.eye_relief_mm, d_l = device.gap_mm, pitch = device.lens_pitch_mm;
    inv_f = 1.0 / device.focal_mm;
    cos_t = std::cos(device.rotation_rad), sin_t = std::sin(device.rotation_rad);
    o = device.lattice_offset_mm;
    half_w = device.panel[0] / 2.0, half_h = device.panel[1] / 2.0;
    weight = 1.0 / static_cast<double>(pupil.size());
  }

  Rgba operator()(int i, int j) const {
    double r = 0, g = 0, b = 0;
    for (const Vec2& rho : pupil) {
      const double slope_x = sim.tan_x_[i] - rho.x * inv_focus, slope_y = sim.tan_y_[j] - rho.y * inv_focus;
      // Hit point on the lens plane.
      const double qx = eye.offset_mm.x + rho.x + slope_x * d_e, qy = eye.offset_mm.y + rho.y + slope_y * d_e;
      // The lenslet whose square aperture contains it: every point of the (unbounded) sheet has one.
      const double lx = cos_t * (qx - o.x) + sin_t * (qy - o.y), ly = -sin_t * (qx - o.x) + cos_t * (qy - o.y);
      const double m = std::floor(lx / pitch + 0.5) * pitch, n = std::floor(ly / pitch + 0.5) * pitch;
      const double cx = o.x + cos_t * m - sin_t * n, cy = o.y + sin_t * m + cos_t * n;
      // Paraxial thin lens, then on to the display.
      const double sx = qx + (slope_x - (qx - cx) * inv_f) * d_l, sy = qy + (slope_y - (qy - cy) * inv_f) * d_l;
      const Rgba p = sample_bilinear_black_outside(displayed, sx / sim.device_.pixel_pitch_mm.x + half_w,
                                                   half_h - sy / sim.device_.pixel_pitch_mm.y);
      r += p.r, g += p.g, b += p.b;
    }
    return {static_cast<float>(r * weight), static_cast<float>(g * weight), static_cast<float>(b * weight), 1.f};
  }
};

void EyeSimulator::check_displayed(const Image& displayed, const EyeModel& eye) const {
  validate_eye_model(eye);
  if (displayed.width() != device_.panel[0] || displayed.height() != device_.panel[1])
    throw std::invalid_argument(fmt::format("eye simulator: displayed image is {}x{}, the panel is {}x{}",
                                            displayed.width(), displayed.height(), device_.panel[0], device_.panel[1]));
}

Image EyeSimulator::retina(const Image& displayed, const EyeModel& eye) const {
  check_displayed(displayed, eye);
  const RetinaTrace trace(*this, displayed, eye);
  Image out(field_.width, field_.height);
  for_each_row(field_.height, [&](int j) {
    for (int i = 0; i < field_.width; ++i) out.at(i, j) = trace(i, j);
  });
  return out;
}

std::vector<Rgba> EyeSimulator::retina_at(const Image& displayed, const EyeModel& eye,
                                          const std::vector<std::array<int, 2>>& pixels) const {
  check_displayed(displayed, eye);
  for (const auto& p : pixels)
    if (p[0] < 0 || p[1] < 0 || p[0] >= field_.width || p[1] >= field_.height)
      throw std::invalid_argument(fmt::format("eye simulator: retinal pixel ({}, {}) is outside the {}x{} field", p[0],
                                              p[1], field_.width, field_.height));
  const RetinaTrace trace(*this, displayed, eye);
  std::vector<Rgba> out(pixels.size());
  constexpr int chunk = 256;  // pixels per task
  const int chunks = static_cast<int>((pixels.size() + chunk - 1) / chunk);
  for_each_row(chunks, [&](int c) {
    const std::size_t end = std::min(pixels.size(), static_cast<std::size_t>(c + 1) * chunk);
    for (std::size_t k = static_cast<std::size_t>(c) * chunk; k < end; ++k) out[k] = trace(pixels[k][0], pixels[k][1]);
  });
  return out;
}

Image EyeSimulator::ideal(const EyeModel& eye, const SceneDepth* scene) const {
  validate_eye_model(eye);
  const auto pupil = pupil_samples(eye.pupil_mm, eye.pupil_samples_per_axis);
  const double inv_focus = 1.0 / eye.focus_mm;
  const double d_r = render_distance_mm_;
  const double weight = 1.0 / static_cast<double>(pupil.size());
  const DisparitySurface* surface =
      scene && scene->surface && !scene->surface->unknown() ? scene->surface.get() : nullptr;
  // Per pupil sample, the shift of the view per unit of disparity for rays through that point.
  std::vector<Vec2> gains;
  if (surface)
    for (const Vec2& rho : pupil)
      gains.push_back(pupil_gain(scene->geometry, {eye.offset_mm.x + rho.x, eye.offset_mm.y + rho.y}));
  Image out(field_.width, field_.height);
  for_each_row(field_.height, [&](int j) {
    for (int i = 0; i < field_.width; ++i) {
      double r = 0, g = 0, b = 0;
      for (std::size_t k = 0; k < pupil.size(); ++k) {
        const Vec2& rho = pupil[k];
        const double vx = eye.offset_mm.x + rho.x + (tan_x_[i] - rho.x * inv_focus) * d_r;
        const double vy = eye.offset_mm.y + rho.y + (tan_y_[j] - rho.y * inv_focus) * d_r;
        Vec2 uv{(vx - screen_centre_mm_.x) / screen_size_mm_.x + 0.5,
                0.5 - (vy - screen_centre_mm_.y) / screen_size_mm_.y};
        if (surface) uv = surface->hit(uv, gains[k]);
        if (uv.x < 0.0 || uv.x > 1.0 || uv.y < 0.0 || uv.y > 1.0) continue;  // beside the screen: black
        const Rgba p = sample_bilinear(band_limited_view_, uv.x, uv.y);
        r += p.r, g += p.g, b += p.b;
      }
      out.at(i, j) = {static_cast<float>(r * weight), static_cast<float>(g * weight), static_cast<float>(b * weight),
                      1.f};
    }
  });
  return out;
}

std::vector<std::uint8_t> EyeSimulator::view_region_mask(const EyeModel& eye,
                                                         const std::vector<std::uint8_t>& view_mask,
                                                         const SceneDepth* scene) const {
  if (view_mask.size() != static_cast<std::size_t>(view_width_) * static_cast<std::size_t>(view_height_))
    throw std::invalid_argument(fmt::format("eye simulator: a region mask of {} values for a {}x{} view",
                                            view_mask.size(), view_width_, view_height_));
  const DisparitySurface* surface =
      scene && scene->surface && !scene->surface->unknown() ? scene->surface.get() : nullptr;
  const Vec2 gain = surface ? pupil_gain(scene->geometry, eye.offset_mm) : Vec2{};
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(field_.width) * static_cast<std::size_t>(field_.height), 0);
  for (int j = 0; j < field_.height; ++j) {
    for (int i = 0; i < field_.width; ++i) {
      const double vx = eye.offset_mm.x + tan_x_[i] * render_distance_mm_;
      const double vy = eye.offset_mm.y + tan_y_[j] * render_distance_mm_;
      Vec2 uv{(vx - screen_centre_mm_.x) / screen_size_mm_.x + 0.5,
              0.5 - (vy - screen_centre_mm_.y) / screen_size_mm_.y};
      if (surface) uv = surface->hit(uv, gain);
      if (uv.x < 0.0 || uv.x >= 1.0 || uv.y < 0.0 || uv.y >= 1.0) continue;
      const int x = std::min(view_width_ - 1, static_cast<int>(uv.x * view_width_));
      const int y = std::min(view_height_ - 1, static_cast<int>(uv.y * view_height_));
      mask[static_cast<std::size_t>(j) * static_cast<std::size_t>(field_.width) + static_cast<std::size_t>(i)] =
          view_mask[static_cast<std::size_t>(y) * static_cast<std::size_t>(view_width_) + static_cast<std::size_t>(x)]
              ? 1
              : 0;
    }
  }
  return mask;
}

std::vector<std::uint8_t> EyeSimulator::on_screen_mask(const EyeModel& eye) const {
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(field_.width) * static_cast<std::size_t>(field_.height));
  for (int j = 0; j < field_.height; ++j) {
    for (int i = 0; i < field_.width; ++i) {
      const double vx = eye.offset_mm.x + tan_x_[i] * render_distance_mm_;
      const double vy = eye.offset_mm.y + tan_y_[j] * render_distance_mm_;
      const bool inside = std::abs(vx - screen_centre_mm_.x) <= screen_size_mm_.x / 2 &&
                          std::abs(vy - screen_centre_mm_.y) <= screen_size_mm_.y / 2;
      mask[static_cast<std::size_t>(j) * static_cast<std::size_t>(field_.width) + static_cast<std::size_t>(i)] =
          inside ? 1 : 0;
    }
  }
  return mask;
}

std::vector<std::uint8_t> EyeSimulator::clear_field_mask(double pupil_mm) const {
  EyeModel relaxed;
  relaxed.pupil_mm = pupil_mm;
  validate_eye_model(relaxed);
  // The rim of the pupil bounds the bundle: sample it densely enough that no lens is skipped between samples.
  std::vector<Vec2> rim;
  constexpr int rim_samples = 64;
  for (int k = 0; k < rim_samples; ++k) {
    const double phi = 2 * std::numbers::pi * k / rim_samples;
    rim.push_back({pupil_mm / 2 * std::cos(phi), pupil_mm / 2 * std::sin(phi)});
  }
  const double cos_t = std::cos(device_.rotation_rad), sin_t = std::sin(device_.rotation_rad);
  const Vec2 o = device_.lattice_offset_mm;
  const double pitch = device_.lens_pitch_mm, d_e = device_.eye_relief_mm;
  const auto lit = [&](double qx, double qy) {
    const double lx = cos_t * (qx - o.x) + sin_t * (qy - o.y), ly = -sin_t * (qx - o.x) + cos_t * (qy - o.y);
    const int m = static_cast<int>(std::floor(lx / pitch + 0.5)), n = static_cast<int>(std::floor(ly / pitch + 0.5));
    return m >= device_.first_lens[0] && m < device_.first_lens[0] + device_.lenses[0] && n >= device_.first_lens[1] &&
           n < device_.first_lens[1] + device_.lenses[1];
  };
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(field_.width) * static_cast<std::size_t>(field_.height));
  for (int j = 0; j < field_.height; ++j) {
    for (int i = 0; i < field_.width; ++i) {
      // The lit block is convex (a rotated rectangle of lenses), so the rim deciding is enough.
      const double cx = tan_x_[i] * d_e, cy = tan_y_[j] * d_e;
      bool clear = lit(cx, cy);
      for (std::size_t k = 0; clear && k < rim.size(); ++k) clear = lit(cx + rim[k].x, cy + rim[k].y);
      mask[static_cast<std::size_t>(j) * static_cast<std::size_t>(field_.width) + static_cast<std::size_t>(i)] =
          clear ? 1 : 0;
    }
  }
  return mask;
}

SimulationResult EyeSimulator::simulate(const Image& displayed, const EyeModel& eye, const SceneDepth* scene) const {
  SimulationResult result;
  result.retina = retina(displayed, eye);
  result.ideal = ideal(eye, scene);
  const auto on_screen = on_screen_mask(eye);
  result.evaluated = clear_field_mask(eye.pupil_mm);
  std::size_t on_screen_count = 0, evaluated_count = 0;
  for (std::size_t k = 0; k < on_screen.size(); ++k) {
    result.evaluated[k] &= on_screen[k];
    on_screen_count += on_screen[k];
    evaluated_count += result.evaluated[k];
  }
  if (evaluated_count == 0)
    throw std::invalid_argument(fmt::format(
        "eye simulator: a {} mm pupil sees no part of the screen through lit lenses only (pupil too large for this "
        "lens block?)",
        eye.pupil_mm));
  result.psnr_db = psnr_db(result.retina, result.ideal, result.evaluated);
  result.psnr_full_screen_db = psnr_db(result.retina, result.ideal, on_screen);
  result.evaluated_fraction = static_cast<double>(evaluated_count) / static_cast<double>(on_screen_count);
  return result;
}

double psnr_db(const Image& a, const Image& b, const std::vector<std::uint8_t>& mask) {
  if (a.width() != b.width() || a.height() != b.height())
    throw std::invalid_argument(
        fmt::format("psnr: image sizes differ ({}x{} vs {}x{})", a.width(), a.height(), b.width(), b.height()));
  if (!mask.empty() && mask.size() != a.pixels().size())
    throw std::invalid_argument("psnr: mask size does not match the images");
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t k = 0; k < a.pixels().size(); ++k) {
    if (!mask.empty() && !mask[k]) continue;
    const Rgba &p = a.pixels()[k], &q = b.pixels()[k];
    const double dr = p.r - q.r, dg = p.g - q.g, db = p.b - q.b;
    sum += dr * dr + dg * dg + db * db;
    ++count;
  }
  if (count == 0) throw std::invalid_argument("psnr: no pixels selected");
  const double mse = sum / (3.0 * static_cast<double>(count));
  return mse == 0.0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(1.0 / mse);
}

}  // namespace nelf
