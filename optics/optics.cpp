#include "optics/optics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace nelf::optics {

int floor_to_int(double x, const char* what) {
  const double floored = std::floor(x);
  // The range test is written so that NaN fails it too.
  if (!(floored >= static_cast<double>(std::numeric_limits<int>::min()) &&
        floored <= static_cast<double>(std::numeric_limits<int>::max())))
    throw std::range_error(std::string(what) + " is out of range: " + std::to_string(x));
  return static_cast<int>(floored);
}

double gap_mm(double focal_mm, double image_mm, double eye_relief_mm) {
  const double span = image_mm - eye_relief_mm;
  return focal_mm * span / (focal_mm + span);
}

double magnification(double focal_mm, double image_mm, double eye_relief_mm) {
  return 1.0 + (image_mm - eye_relief_mm) / focal_mm;
}

namespace {
double gap_of(const AxisGeometry& g) { return g.gap_mm ? *g.gap_mm : gap_mm(g.focal_mm, g.image_mm, g.eye_relief_mm); }
double magnification_of(const AxisGeometry& g) {
  // With a fixed gap the magnification follows the thin-lens image of the display: M = f/(f − d_l)
  // equals Eq. 2 when d_l comes from Eq. 1.
  if (g.gap_mm) return g.focal_mm / (g.focal_mm - *g.gap_mm);
  return magnification(g.focal_mm, g.image_mm, g.eye_relief_mm);
}
}  // namespace

double elemental_image_mm(const AxisGeometry& g) {
  const double d_l = gap_of(g);
  return std::min((g.eye_relief_mm + d_l) / g.eye_relief_mm * g.lens_pitch_mm, g.display_mm);
}

double lenses_fitting(const AxisGeometry& g) { return g.display_mm / elemental_image_mm(g); }

int lenses_used(const AxisGeometry& g) {
  // A small epsilon keeps an exact fit (w_s = N Δw_s) from flooring to N − 1 through rounding.
  return floor_to_int(lenses_fitting(g) + 1e-9, "lens count");
}

double field_of_view_rad(const AxisGeometry& g) {
  const double lens_limit = lenses_used(g) * g.lens_pitch_mm / (2.0 * g.eye_relief_mm);
  const double display_limit = magnification_of(g) * g.display_mm / (2.0 * g.image_mm);
  return 2.0 * std::atan(std::min(lens_limit, display_limit));
}

int resolution_px(const AxisGeometry& g) {
  const double by_lenses =
      g.image_mm * lenses_used(g) * g.lens_pitch_mm / (g.eye_relief_mm * magnification_of(g) * g.pixel_pitch_mm);
  const double by_pixels = g.display_mm / g.pixel_pitch_mm;
  return floor_to_int(std::min(by_lenses, by_pixels) + 1e-9, "spatial resolution");
}

double eye_box_mm(const AxisGeometry& g) {
  const double d_l = gap_of(g);
  return std::abs(g.image_mm / (g.image_mm - g.eye_relief_mm) * g.lens_pitch_mm -
                  g.eye_relief_mm / d_l * elemental_image_mm(g));
}

namespace {
double lens_blur_term(const AxisGeometry& g, double depth_mm) {
  return std::abs(depth_mm - g.image_mm) / (g.image_mm - g.eye_relief_mm) * g.lens_pitch_mm;
}
double pixel_blur_term(const AxisGeometry& g, double depth_mm) {
  return (depth_mm - g.eye_relief_mm) / gap_of(g) * g.pixel_pitch_mm;
}
}  // namespace

double defocus_blur_mm(const AxisGeometry& g, double depth_mm) {
  return std::max(lens_blur_term(g, depth_mm), pixel_blur_term(g, depth_mm));
}

int resolution_at_depth_px(const AxisGeometry& g, double depth_mm) {
  const double half_fov = field_of_view_rad(g) / 2.0;
  return floor_to_int(2.0 * depth_mm * std::tan(half_fov) / defocus_blur_mm(g, depth_mm), "resolution at depth");
}

DepthOfField depth_of_field(const AxisGeometry& g) {
  // Both terms are linear in d': lens term L(d') = |d' − d_o| · a, pixel term P(d') = (d' − d_e) · b.
  // Near: solve (d_o − d') a = (d' − d_e) b; far (d' > d_o): (d' − d_o) a = (d' − d_e) b, which has a
  // solution only when a > b (the lens term grows faster), else the depth of field reaches infinity.
  const double a = g.lens_pitch_mm / (g.image_mm - g.eye_relief_mm);
  const double b = g.pixel_pitch_mm / gap_of(g);
  DepthOfField dof;
  dof.near_mm = (g.image_mm * a + g.eye_relief_mm * b) / (a + b);
  if (a > b) dof.far_mm = (g.image_mm * a - g.eye_relief_mm * b) / (a - b);
  return dof;
}

double eye_blur_mm(double accommodation_mm, double depth_mm, double pupil_mm) {
  return std::abs(accommodation_mm - depth_mm) / accommodation_mm * pupil_mm;
}

int views_in_pupil(double accommodation_mm, double eye_relief_mm, double pupil_mm, double lens_pitch_mm) {
  const double ratio =
      std::isinf(accommodation_mm) ? 1.0 : std::abs(accommodation_mm - eye_relief_mm) / accommodation_mm;
  return floor_to_int(ratio * pupil_mm / lens_pitch_mm + 1e-9, "views in the pupil");
}

double simple_magnifier_min_focal_mm(double f_number, double eye_box_mm, double eye_relief_mm, double display_mm) {
  const double n = f_number;
  return (n * eye_box_mm + std::sqrt(n * n * eye_box_mm * eye_box_mm + 4.0 * n * eye_relief_mm * display_mm)) / 2.0;
}

double diffraction_pitch_um(double wavelength_nm, double gap_mm_value, double lens_pitch_mm) {
  // λ in mm = nm · 1e-6; result in µm = mm · 1e3.
  return wavelength_nm * 1e-6 * gap_mm_value / lens_pitch_mm * 1e3;
}

namespace magnifier {
double field_of_view_rad(const AxisGeometry& g) {
  const double lens_limit = g.lens_pitch_mm / (2.0 * g.eye_relief_mm);
  const double display_limit = magnification_of(g) * g.display_mm / (2.0 * g.image_mm);
  return 2.0 * std::atan(std::min(lens_limit, display_limit));
}
int resolution_px(const AxisGeometry& g) {
  const double by_lens = g.image_mm * g.lens_pitch_mm / (g.eye_relief_mm * magnification_of(g) * g.pixel_pitch_mm);
  const double by_pixels = g.display_mm / g.pixel_pitch_mm;
  return floor_to_int(std::min(by_lens, by_pixels) + 1e-9, "spatial resolution");
}
double eye_box_mm(const AxisGeometry& g) {
  return std::abs(g.image_mm / (g.image_mm - g.eye_relief_mm) * g.lens_pitch_mm -
                  g.eye_relief_mm / gap_of(g) * g.display_mm);
}
}  // namespace magnifier

}  // namespace nelf::optics
