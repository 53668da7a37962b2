#pragma once
// The per-pixel elemental-image mapping of DESIGN.md §3, on the CPU in double precision.
// EyeMapping holds everything derived once from a profile for one eye; the GL shaders receive the
// same numbers as uniforms (compositor/gl/gl_compositor.cpp), the CPU reference and the eye simulator
// call these functions directly, so there is exactly one definition of the geometry.
//
// Coordinates per eye, millimetres: origin at the pupil centre, x right, y up, z towards the
// display. Lens array at z = d_e, display at z = d_e + d_l, emulated screen at z = d_r.
#include <array>
#include <optional>

#include "optics/profile.hpp"

namespace nelf {

struct EyeMapping {
  Eye eye = Eye::left;
  std::array<int, 2> panel{0, 0};  // display resolution (pixels)
  Vec2 pixel_pitch_mm;
  Vec2 shift_px;            // calibration shift: the image moves right/down by this much
  double rotation_rad = 0;  // lens lattice rotation (lens_array + calibration); for stock devices the image's
  double rotation_cos = 1, rotation_sin = 0;
  bool has_lens_array = false;

  // Lens array devices.
  double eye_relief_mm = 0;             // d_e
  double gap_mm = 0;                    // d_l
  double render_distance_mm = 0;        // d_r: where the emulated screen is and where the eye must focus
  double lens_pitch_mm = 0;             // w_l · k (calibrated pitch)
  Vec2 lattice_offset_mm;               // o, including the half-lens shift for an even lens count
  std::array<int, 2> lenses{0, 0};      // N_l per axis: the central block that is lit
  std::array<int, 2> first_lens{0, 0};  // lowest lens index (m, n) of that block
  Vec2 screen_centre_mm;                // emulated screen centre in this eye's coordinates (z = d_r)
  Vec2 screen_size_mm;                  // its width and height

  // Stock devices: the view is fitted into the panel (aspect kept), this is its size on the panel.
  Vec2 view_size_mm;
};

// Derives the mapping for `eye` showing content of display aspect `content_aspect` (width/height).
// Throws ProfileError when the geometry cannot work (e.g. the screen does not fit the field of view).
EyeMapping make_eye_mapping(const Profile& profile, Eye eye, double content_aspect);

// Position on the display (mm, relative to the point straight ahead of the pupil) of the continuous
// pixel coordinate (x, y); pixel (i, j) has its centre at (i + 0.5, j + 0.5), y grows downwards.
Vec2 display_position_mm(const EyeMapping& m, double x, double y);

// Centre (lens plane, mm) of the lens in front of display position s, whether its elemental image is
// lit or not.
Vec2 lens_centre_in_front(const EyeMapping& m, Vec2 s);

// Centre (lens plane, mm) of the lens owning display position s, or nothing when s is outside the
// central N_l,x × N_l,y block of elemental images.
std::optional<Vec2> owner_lens_centre(const EyeMapping& m, Vec2 s);

// Texture coordinate (u right, t down, both in [0,1]) of the view shown at display position s, or
// nothing where the display is black there.
std::optional<Vec2> view_coordinate(const EyeMapping& m, Vec2 s);

// Convenience: view_coordinate at continuous pixel coordinate (x, y).
inline std::optional<Vec2> view_coordinate_at_pixel(const EyeMapping& m, double x, double y) {
  return view_coordinate(m, display_position_mm(m, x, y));
}

// The extent of one display pixel on the view, in texture units per axis: the footprint the
// antialiasing filter must match (DESIGN.md §4).
Vec2 pixel_footprint_uv(const EyeMapping& m);

// The fraction of the panel's pixels that show the view, measured at pixel centres (on a regular
// grid of about 2^14 of them for large panels): the rest stay black. It is what the eye still gets
// of the emulated screen; `nelf calibrate` refuses changes that leave too little of it.
double lit_fraction(const EyeMapping& m);

// d_r from the profile: screen.distance_mm (0 = virtual_image_mm), pulled in to the far point
// 1000/|S| mm of a myope's prescription S < 0.
double render_distance_mm(const Profile& profile);

// Lens–display gap d_l: lens_array.gap_mm, or Eq. 1.
double lens_gap_mm(const Profile& profile);

}  // namespace nelf
