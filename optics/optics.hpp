#pragma once
// The near-eye light field display model of DESIGN.md §2 (Lanman & Luebke, "Near-Eye Light Field
// Displays", SIGGRAPH Asia 2013). Every quantity is per axis: call with the display's width for the
// horizontal figure and its height for the vertical one. Lengths in millimetres, angles in radians
// unless the name says degrees.
//
// A single magnifier of width w_l is the same model with one lens whose elemental image is the whole
// display (Δw_s = w_s, N_l = 1): see the `Magnifier` overloads.
#include <optional>

namespace nelf::optics {

// Inputs of one axis.
struct AxisGeometry {
  double display_mm = 0.0;       // w_s: microdisplay extent along this axis
  double pixel_pitch_mm = 0.0;   // p
  double lens_pitch_mm = 0.0;    // w_l (lens array pitch, or the magnifier's width)
  double focal_mm = 0.0;         // f
  double eye_relief_mm = 0.0;    // d_e
  double image_mm = 0.0;         // d_o: virtual image distance from the eye
  std::optional<double> gap_mm;  // d_l when fixed by the hardware; Eq. 1 otherwise
};

// ⌊x⌋ as an int. Throws
// std::range_error naming `what` when x is not finite or ⌊x⌋ lies outside int's range, so that
// no figure of an absurd geometry is cast with undefined behaviour; profile validation refuses such
// geometries first (optics/profile.cpp), so a loaded profile never throws here.
int floor_to_int(double x, const char* what);

// Eq. 1: lens–display gap placing the virtual image at d_o.
double gap_mm(double focal_mm, double image_mm, double eye_relief_mm);
// Eq. 2: magnification M = 1 + (d_o − d_e)/f.
double magnification(double focal_mm, double image_mm, double eye_relief_mm);
// Eq. 6: elemental image width Δw_s = min((d_e + d_l)/d_e · w_l, w_s).
double elemental_image_mm(const AxisGeometry& g);
// Eq. 6: w_s / Δw_s, the lenses that fit (unfloored, so that validation can bound it before it
// becomes an int).
double lenses_fitting(const AxisGeometry& g);
// Eq. 6: lenses used N_l = ⌊w_s / Δw_s⌋.
int lenses_used(const AxisGeometry& g);
// Eq. 7: field of view α (radians).
double field_of_view_rad(const AxisGeometry& g);
// Eq. 8: spatial resolution N_p (pixels).
int resolution_px(const AxisGeometry& g);
// Eq. 9: eye box w_e.
double eye_box_mm(const AxisGeometry& g);
// Eq. 12: defocus blur c' (mm, on a plane at distance d') of the display's image.
double defocus_blur_mm(const AxisGeometry& g, double depth_mm);
// Eq. 13: resolution N'_p at distance d'.
int resolution_at_depth_px(const AxisGeometry& g, double depth_mm);
// Depth of field: nearest and farthest d' where the lens term of Eq. 12 does not exceed the pixel
// term. far is nullopt for infinity.
struct DepthOfField {
  double near_mm = 0.0;
  std::optional<double> far_mm;
};
DepthOfField depth_of_field(const AxisGeometry& g);
// Eq. 14: retinal blur c_a of a point at d' for an eye of pupil a accommodated at d_a.
double eye_blur_mm(double accommodation_mm, double depth_mm, double pupil_mm);
// Eq. 15: views entering the pupil N_v (accommodation_mm = infinity allowed).
int views_in_pupil(double accommodation_mm, double eye_relief_mm, double pupil_mm, double lens_pitch_mm);
// Appendix A: smallest focal length of a simple magnifier with f-number N giving eye box w_e for a
// display of width w_s at eye relief d_e.
double simple_magnifier_min_focal_mm(double f_number, double eye_box_mm, double eye_relief_mm, double display_mm);
// Diffraction limit: the smallest useful pixel pitch p ≥ λ d_l / w_l, in micrometres.
double diffraction_pitch_um(double wavelength_nm, double gap_mm, double lens_pitch_mm);

// The single-magnifier case (Eqs. 3–5): one lens of width w_l, Δw_s = w_s.
namespace magnifier {
double field_of_view_rad(const AxisGeometry& g);
int resolution_px(const AxisGeometry& g);
double eye_box_mm(const AxisGeometry& g);
}  // namespace magnifier

}  // namespace nelf::optics
