// The per-pixel mapping's inputs and shared geometry (DESIGN.md §3), included by elemental.frag and
// border_strips.vert (nelf splices `#include` lines itself; GL drivers have no include).
//
// One std140 block, mirrored field for field by nelf::shader::MappingBlock
// (compositor/gl/shader_interface.hpp, whose offsets are static_asserted; tests/compositor/gl
// checks them against the linked program). Keep both in the same order.
layout(std140, binding = 0) uniform Mapping {
  vec2 u_texture_scale;    // u_view coordinate = uv * scale + offset: the prefiltered
  vec2 u_texture_offset;   // texture extends beyond the screen (black margin)
  vec2 u_region_origin;    // lower-left corner of the eye's region in the target (pixels)
  vec2 u_panel;            // panel resolution
  vec2 u_pixel_pitch;      // mm
  vec2 u_shift;            // calibration shift (pixels, right/down)
  vec2 u_rotation;         // cos, sin of the lattice (or, stock, image) rotation
  vec2 u_lattice_offset;   // mm
  vec2 u_screen_centre;    // mm
  vec2 u_screen_size;      // mm
  vec2 u_view_size;        // mm, stock devices
  ivec2 u_first_lens;
  ivec2 u_lenses;
  float u_to_lens_plane;   // d_e / (d_e + d_l)
  float u_lens_pitch;      // mm, calibrated
  float u_chief_ray_scale; // (d_r - d_e) / d_l
  int u_cut_outside;       // 1: sampling the view itself, black outside the screen
  int u_has_lens_array;    // 0: a stock device (the view magnified, no lenslets)
};

// v rotated by the lattice's angle (sign_ 1) or back (sign_ -1).
vec2 rotate(vec2 v, float sign_) {
  const float c = u_rotation.x, s = sign_ * u_rotation.y;
  return vec2(c * v.x - s * v.y, s * v.x + c * v.y);
}

// Pixel position (x right, y down from the top, pixel centres at +½) to display position (mm, y up).
vec2 display_position(vec2 pixel) {
  return vec2((pixel.x - 0.5 * u_panel.x - u_shift.x) * u_pixel_pitch.x,
              (0.5 * u_panel.y - pixel.y + u_shift.y) * u_pixel_pitch.y);
}

// Position in the lens lattice (units of the lens pitch, rotated frame) of display position s.
vec2 lattice_position(vec2 s) { return rotate(s * u_to_lens_plane - u_lattice_offset, -1.0) / u_lens_pitch; }

// The inverse of lattice_position ∘ display_position: lattice coordinates to pixel coordinates.
vec2 lattice_to_pixel(vec2 q) {
  const vec2 s = (u_lattice_offset + rotate(q * u_lens_pitch, 1.0)) / u_to_lens_plane;
  return vec2(s.x / u_pixel_pitch.x + 0.5 * u_panel.x + u_shift.x, 0.5 * u_panel.y + u_shift.y - s.y / u_pixel_pitch.y);
}
