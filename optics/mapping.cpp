#include "optics/mapping.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "optics/optics.hpp"

namespace nelf {

namespace {

Vec2 rotate(Vec2 v, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * v.x - s * v.y, s * v.x + c * v.y};
}

// Rotation by the mapping's angle (sign = +1) or its inverse (sign = -1), without trigonometry per pixel.
Vec2 rotate(const EyeMapping& m, Vec2 v, double sign) {
  const double c = m.rotation_cos, s = sign * m.rotation_sin;
  return {c * v.x - s * v.y, s * v.x + c * v.y};
}

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

}  // namespace

double lens_gap_mm(const Profile& profile) {
  const auto& lens = profile.lens_array.value();
  return lens.gap_mm
             ? *lens.gap_mm
             : optics::gap_mm(lens.focal_length_mm, profile.viewing.virtual_image_mm, profile.viewing.eye_relief_mm);
}

double render_distance_mm(const Profile& profile) {
  double d_r = profile.screen.distance_mm > 0.0 ? profile.screen.distance_mm : profile.viewing.virtual_image_mm;
  const double s = profile.correction.prescription_diopters;
  if (s < 0.0) d_r = std::min(d_r, 1000.0 / -s);  // a myope cannot focus beyond the far point
  return d_r;
}

EyeMapping make_eye_mapping(const Profile& profile, Eye eye, double content_aspect) {
  if (!(content_aspect > 0.0) || !std::isfinite(content_aspect))
    throw std::invalid_argument(fmt::format("content aspect ratio must be > 0, got {}", content_aspect));
  const EyeCalibration& cal = profile.eye_calibration(eye);
  EyeMapping m;
  m.eye = eye;
  m.panel = profile.display.resolution;
  m.pixel_pitch_mm = profile.display.pixel_pitch_mm;
  m.shift_px = cal.shift_px;
  m.has_lens_array = profile.lens_array.has_value();

  if (!m.has_lens_array) {
    // Stock device: the view fills the panel with its aspect kept, centred (letter/pillar-boxed).
    m.rotation_rad = radians(cal.rotation_deg);
    m.rotation_cos = std::cos(m.rotation_rad);
    m.rotation_sin = std::sin(m.rotation_rad);
    const double w = profile.display.width_mm(), h = profile.display.height_mm();
    if (content_aspect >= w / h)
      m.view_size_mm = {w, w / content_aspect};
    else
      m.view_size_mm = {h * content_aspect, h};
    return m;
  }

  const LensArraySpec& lens = *profile.lens_array;
  m.rotation_rad = radians(lens.rotation_deg + cal.rotation_deg);
  m.rotation_cos = std::cos(m.rotation_rad);
  m.rotation_sin = std::sin(m.rotation_rad);
  m.eye_relief_mm = profile.viewing.eye_relief_mm;
  m.gap_mm = lens_gap_mm(profile);
  m.render_distance_mm = render_distance_mm(profile);
  m.lens_pitch_mm = lens.pitch_mm * cal.pitch_scale;

  Vec2 half_lens;
  double half_fov[2];
  for (int axis = 0; axis < 2; ++axis) {
    const auto g = axis_geometry(profile, axis);
    m.lenses[axis] = std::max(1, optics::lenses_used(g));
    m.first_lens[axis] = -(m.lenses[axis] / 2);
    (axis == 0 ? half_lens.x : half_lens.y) = m.lenses[axis] % 2 == 0 ? 0.5 : 0.0;
    half_fov[axis] = optics::field_of_view_rad(g) / 2.0;
  }
  // An even lens count puts the axis between two lenses, so the used block stays centred.
  const Vec2 centring = rotate({half_lens.x * m.lens_pitch_mm, half_lens.y * m.lens_pitch_mm}, m.rotation_rad);
  m.lattice_offset_mm = {lens.offset_mm.x + centring.x, lens.offset_mm.y + centring.y};

  // The emulated screen: shared by both eyes, so its centre lies half the IPD towards the nose.
  const double nasal = profile.screen.converge ? profile.viewing.ipd_mm / 2.0 : 0.0;
  m.screen_centre_mm = {eye == Eye::left ? nasal : -nasal, 0.0};
  const double d_r = m.render_distance_mm;
  double width = profile.screen.width_mm;
  if (width <= 0.0) {
    // Largest rectangle of the content's aspect inside both eyes' fields of view.
    const double max_w = 2.0 * (d_r * std::tan(half_fov[0]) - nasal);
    const double max_h = 2.0 * d_r * std::tan(half_fov[1]);
    if (max_w <= 0.0)
      throw ProfileError(fmt::format(
          "{}: screen: no screen fits both eyes' field of view at {:.0f} mm with ipd_mm {} (set screen.converge = "
          "false or a larger screen.distance_mm)",
          profile.source, d_r, profile.viewing.ipd_mm));
    width = std::min(max_w, max_h * content_aspect);
  }
  m.screen_size_mm = {width, width / content_aspect};
  return m;
}

Vec2 display_position_mm(const EyeMapping& m, double x, double y) {
  return {(x - m.panel[0] / 2.0 - m.shift_px.x) * m.pixel_pitch_mm.x,
          (m.panel[1] / 2.0 - y + m.shift_px.y) * m.pixel_pitch_mm.y};
}

namespace {
// The lattice index (m, n) of the lens in front of display position s.
std::array<int, 2> lens_in_front(const EyeMapping& m, Vec2 s) {
  // Each lens's elemental image is the lens lattice projected from the pupil onto the display.
  const double to_lens_plane = m.eye_relief_mm / (m.eye_relief_mm + m.gap_mm);
  const Vec2 q =
      rotate(m, {s.x * to_lens_plane - m.lattice_offset_mm.x, s.y * to_lens_plane - m.lattice_offset_mm.y}, -1.0);
  return {static_cast<int>(std::floor(q.x / m.lens_pitch_mm + 0.5)),
          static_cast<int>(std::floor(q.y / m.lens_pitch_mm + 0.5))};
}

Vec2 centre_of_lens(const EyeMapping& m, std::array<int, 2> lens) {
  const Vec2 c = rotate(m, {lens[0] * m.lens_pitch_mm, lens[1] * m.lens_pitch_mm}, 1.0);
  return Vec2{m.lattice_offset_mm.x + c.x, m.lattice_offset_mm.y + c.y};
}
}  // namespace

Vec2 lens_centre_in_front(const EyeMapping& m, Vec2 s) { return centre_of_lens(m, lens_in_front(m, s)); }

std::optional<Vec2> owner_lens_centre(const EyeMapping& m, Vec2 s) {
  const auto [lens_m, lens_n] = lens_in_front(m, s);
  if (lens_m < m.first_lens[0] || lens_m >= m.first_lens[0] + m.lenses[0] || lens_n < m.first_lens[1] ||
      lens_n >= m.first_lens[1] + m.lenses[1])
    return std::nullopt;
  return centre_of_lens(m, {lens_m, lens_n});
}

std::optional<Vec2> view_coordinate(const EyeMapping& m, Vec2 s) {
  Vec2 uv;
  if (!m.has_lens_array) {
    const Vec2 r = rotate(m, s, -1.0);
    uv = {r.x / m.view_size_mm.x + 0.5, 0.5 - r.y / m.view_size_mm.y};
  } else {
    const auto c = owner_lens_centre(m, s);
    if (!c) return std::nullopt;
    // Chief ray from the pixel through the lens centre, continued back to the screen plane.
    const double k = (m.render_distance_mm - m.eye_relief_mm) / m.gap_mm;
    const Vec2 v{c->x + (s.x - c->x) * k, c->y + (s.y - c->y) * k};
    uv = {(v.x - m.screen_centre_mm.x) / m.screen_size_mm.x + 0.5,
          0.5 - (v.y - m.screen_centre_mm.y) / m.screen_size_mm.y};
  }
  if (uv.x < 0.0 || uv.x > 1.0 || uv.y < 0.0 || uv.y > 1.0) return std::nullopt;
  return uv;
}

double lit_fraction(const EyeMapping& m) {
  constexpr double kSamples = 16384.0;
  const double pixels = static_cast<double>(m.panel[0]) * m.panel[1];
  if (!(pixels > 0.0)) return 0.0;
  const int stride = std::max(1, static_cast<int>(std::ceil(std::sqrt(pixels / kSamples))));
  std::size_t lit = 0, total = 0;
  for (int y = stride / 2; y < m.panel[1]; y += stride)
    for (int x = stride / 2; x < m.panel[0]; x += stride, ++total)
      if (view_coordinate_at_pixel(m, x + 0.5, y + 0.5)) ++lit;
  return total ? static_cast<double>(lit) / static_cast<double>(total) : 0.0;
}

Vec2 pixel_footprint_uv(const EyeMapping& m) {
  if (!m.has_lens_array) return {m.pixel_pitch_mm.x / m.view_size_mm.x, m.pixel_pitch_mm.y / m.view_size_mm.y};
  const double k = (m.render_distance_mm - m.eye_relief_mm) / m.gap_mm;
  return {m.pixel_pitch_mm.x * k / m.screen_size_mm.x, m.pixel_pitch_mm.y * k / m.screen_size_mm.y};
}

}  // namespace nelf
