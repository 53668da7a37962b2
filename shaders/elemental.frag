#version 450 core
// One eye's elemental images: the per-pixel mapping of DESIGN.md §3, the same math as
// optics/mapping.cpp (view_coordinate) in float. Pixel positions are taken relative to the
// panel's pixel grid, so float keeps sub-micrometre precision.
//
// Compiled in eight variants (compositor/gl/shader_programs.cpp lists them, and the build validates
// each): as is for pass 1 (point samples over the whole region), with NELF_AREA_SAMPLE for the
// border strips, NELF_COORDINATE_MAP for pass 1's coordinate map, NELF_AREA_SAMPLE +
// NELF_RECORD_TAPS for the CPU composite table, NELF_DEPTH (with or without NELF_AREA_SAMPLE)
// for pass 1 and the strips of the depth-aware composite, NELF_DEPTH_MAP for its pass 1's
// depth coordinate map (elemental_depth_lookup.frag), NELF_AREA_SAMPLE + NELF_DEPTH_HITS for
// the strips after that pass 1, and those + NELF_RECORD_TAPS for the CPU depth-aware table. Compile-time switches: llvmpipe would otherwise evaluate both sides
// of a run-time choice for every pixel.
//
// Memory layout: row 0 of the target region is the top row of the eye image (as in nelf::Image);
// the view textures likewise hold the image's top row first, so t (down) is the texture's y.

layout(binding = 0) uniform sampler2D u_view;  // the view, or its footprint-prefiltered version
#include "mapping.glsl"

// Sub-samples per axis (1, 2 or 4): a compile-time constant, so the loops below unroll (llvmpipe
// runs a loop bounded by a uniform with per-lane masks, which cost ~as much as the taps).
#ifndef NELF_SUBSAMPLES
#define NELF_SUBSAMPLES 1
#endif
const int u_subsamples = NELF_SUBSAMPLES;

out vec4 colour;

#if defined(NELF_DEPTH) || defined(NELF_DEPTH_MAP) || defined(NELF_DEPTH_HITS)
#include "depth_search.glsl"
#endif

#ifdef NELF_DEPTH_HITS
// The border strips after the depth-aware pass 1 from the depth coordinate map (fsaa 1). Each part
// of a border pixel takes the crossing that pass 1 found for the nearest pixel seen through the same
// lens, rather than searching again: this pixel for its own lens, the pixel one pixel beyond the
// border for a neighbour's. The two rays leave the display less than two pixels apart through the
// same lens, so they meet the screen within two footprints of each other, the scale the prefiltered
// view is already averaged over; they find different crossings only at an edge of the content's
// depth. Searching four times a border pixel cost as much as all of pass 1 on llvmpipe.
layout(binding = 3) uniform sampler2D u_hits;  // R32F, panel-sized, written by elemental_depth_lookup.frag
vec2 g_lattice_position;                       // of the fragment's centre: area_sample's q (one sample)

// The pixel whose crossing the part through `lens` takes (u_hits is panel-sized).
ivec2 hit_pixel(ivec2 lens) {
  const vec2 own = floor(g_lattice_position + 0.5);
  const vec2 across = vec2(lens) - own;  // -1, 0 or 1 per axis
  const vec2 one_pixel = u_pixel_pitch * u_to_lens_plane / u_lens_pitch;  // in lattice units
  const vec2 beyond = mix(g_lattice_position, own + across * (0.5 + one_pixel), notEqual(across, vec2(0.0)));
  return clamp(ivec2(floor(lattice_to_pixel(beyond))), ivec2(0), ivec2(u_panel) - 1);
}
float hit_through(ivec2 lens) { return texelFetch(u_hits, hit_pixel(lens), 0).r; }
#endif

bool inside(vec2 uv) { return all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0))); }

// The view at screen coordinate uv. The prefiltered texture already fades to black across the
// screen's edge over the footprint; the raw view is cut there.
vec3 tap(vec2 uv) {
  if (u_cut_outside != 0 && !inside(uv)) return vec3(0.0);
  return textureLod(u_view, uv * u_texture_scale + u_texture_offset, 0.0).rgb;
}

// Whether lens (m, n) is lit; if so, `uv` is the screen coordinate seen from display position s
// through it.
bool lens_coordinate(vec2 s, ivec2 lens, out vec2 uv) {
  uv = vec2(0.0);
  if (any(lessThan(lens, u_first_lens)) || any(greaterThanEqual(lens, u_first_lens + u_lenses))) return false;
  const vec2 c = u_lattice_offset + rotate(vec2(lens) * u_lens_pitch, 1.0);
  const vec2 v = c + (s - c) * u_chief_ray_scale;  // chief ray back to the screen plane
  uv = vec2((v.x - u_screen_centre.x) / u_screen_size.x + 0.5, 0.5 - (v.y - u_screen_centre.y) / u_screen_size.y);
#ifdef NELF_DEPTH
  uv = surface_uv(uv, (c - (s - c) * u_pupil_per_lens) * u_parallax_gain);
#elif defined(NELF_DEPTH_HITS) && !defined(NELF_RECORD_TAPS)
  uv += (c - (s - c) * u_pupil_per_lens) * u_parallax_gain * hit_through(lens);
#endif
  return true;
}

// The view at display position s as seen through lens (m, n): black outside the lit block or the screen.
vec3 through_lens(vec2 s, ivec2 lens) {
  vec2 uv;
  return lens_coordinate(s, lens, uv) ? tap(uv) : vec3(0.0);
}

// view_coordinate(display_position_mm(x, y)) followed by a tap; black where the display is black.
vec3 point_sample(vec2 pixel) {
  const vec2 s = display_position(pixel);
  if (u_has_lens_array == 0) {
    const vec2 r = rotate(s, -1.0);
    const vec2 uv = vec2(r.x / u_view_size.x + 0.5, 0.5 - r.y / u_view_size.y);
    return tap(uv);
  }
  return through_lens(s, ivec2(floor(lattice_position(s) + 0.5)));
}

#ifdef NELF_RECORD_TAPS
// Where each part of a border pixel taps u_view and with what weight (x, y, weight, 1), instead of
// tapping: the CPU composite table (compositor/cpu/composite_table.hpp) replays them every frame.
// Part 0 is the own lens, 1 the neighbour across x, 2 across y, 3 the diagonal one; weight 0 for a
// part that is absent or falls on a black lens. With NELF_DEPTH_HITS (the depth-aware table), what
// of each part's ray does not change from frame to frame instead: u_part 0–3 its flat-screen point
// and pupil crossing (as the depth coordinate map holds them), 4–7 its weight and the pixel whose
// crossing it takes (x, y).
layout(location = 0) uniform int u_part;
vec4 recorded[4] = vec4[4](vec4(0.0, 0.0, 0.0, 1.0), vec4(0.0, 0.0, 0.0, 1.0), vec4(0.0, 0.0, 0.0, 1.0),
                           vec4(0.0, 0.0, 0.0, 1.0));
void add_part(inout vec3 sum, int part, float weight, vec2 s, ivec2 lens) {
  vec2 uv;
  if (!lens_coordinate(s, lens, uv)) return;
#ifdef NELF_DEPTH_HITS
  const vec2 c = u_lattice_offset + rotate(vec2(lens) * u_lens_pitch, 1.0);
  recorded[part] = u_part < 4 ? vec4(uv, c - (s - c) * u_pupil_per_lens) : vec4(weight, vec2(hit_pixel(lens)), 1.0);
#else
  recorded[part] = vec4(uv * u_texture_scale + u_texture_offset, weight, 1.0);
#endif
}
#else
void add_part(inout vec3 sum, int part, float weight, vec2 s, ivec2 lens) { sum += weight * through_lens(s, lens); }
#endif

// One tap per lens that an `aperture`×`aperture` pixel square centred on `pixel` overlaps: a
// (sub-)pixel straddling an elemental image border mixes both sides by area, as the reference's
// sub-samples do; each part is tapped at its centroid. Interior ones (almost all) take one tap. Exact for an unrotated lattice;
// for a rotated one the aperture is approximated by an axis-aligned square in lattice coordinates.
vec3 area_sample(vec2 pixel, float aperture) {
  if (u_has_lens_array == 0) return point_sample(pixel);
  const vec2 s = display_position(pixel);
  const vec2 q = lattice_position(s);
#ifdef NELF_DEPTH_HITS
  g_lattice_position = q;
#endif
  const vec2 half_pixel = 0.5 * aperture * u_pixel_pitch * u_to_lens_plane / u_lens_pitch;
  const vec2 own = floor(q + 0.5);
  const vec2 lo = q - half_pixel, hi = q + half_pixel;
  // Per axis: which neighbour (±1, or 0 for none) the aperture reaches into, and the split point.
  const vec2 step_ = mix(mix(vec2(0.0), vec2(-1.0), lessThan(lo, own - 0.5)), vec2(1.0), greaterThan(hi, own + 0.5));
  const vec2 border = own + 0.5 * step_;
  // Own part [max(lo, own-½), min(hi, own+½)], neighbour part the rest.
  const vec2 own_lo = max(lo, own - 0.5), own_hi = min(hi, own + 0.5);
  const vec2 own_weight = (own_hi - own_lo) / (hi - lo);
  const vec2 own_centre = 0.5 * (own_lo + own_hi);
  const vec2 other_centre = mix(0.5 * (border + hi), 0.5 * (lo + border), lessThan(step_, vec2(0.0)));
  vec3 sum = vec3(0.0);
  add_part(sum, 0, own_weight.x * own_weight.y, s + rotate((own_centre - q) * u_lens_pitch, 1.0) / u_to_lens_plane,
           ivec2(own));
  if (step_.x != 0.0) {
    const vec2 centre = vec2(other_centre.x, own_centre.y);
    add_part(sum, 1, (1.0 - own_weight.x) * own_weight.y,
             s + rotate((centre - q) * u_lens_pitch, 1.0) / u_to_lens_plane, ivec2(own + vec2(step_.x, 0.0)));
  }
  if (step_.y != 0.0) {
    const vec2 centre = vec2(own_centre.x, other_centre.y);
    add_part(sum, 2, own_weight.x * (1.0 - own_weight.y),
             s + rotate((centre - q) * u_lens_pitch, 1.0) / u_to_lens_plane, ivec2(own + vec2(0.0, step_.y)));
  }
  if (step_.x != 0.0 && step_.y != 0.0) {
    add_part(sum, 3, (1.0 - own_weight.x) * (1.0 - own_weight.y),
             s + rotate((other_centre - q) * u_lens_pitch, 1.0) / u_to_lens_plane, ivec2(own + step_));
  }
  return sum;
}

#if defined(NELF_RECORD_TAPS)
// The border strips' part u_part for the CPU composite table (one sub-sample per pixel); alpha 1
// marks the pixels the strips cover (the target is cleared to 0; with NELF_DEPTH_HITS in passes
// 4–7). One part per pass keeps the target a single panel-sized texture.
void main() {
  area_sample(floor(gl_FragCoord.xy - u_region_origin) + 0.5, 1.0);
  colour = recorded[u_part & 3];
}
#elif defined(NELF_DEPTH_MAP)
// The depth coordinate map (one sample per pixel, lens arrays only): for each pixel, where its chief
// ray meets the flat screen (RG, screen uv) and where it crosses the pupil plane (BA, mm), the two
// inputs of surface_uv that do not change from frame to frame; a screen uv of -1e9 where the display
// is black. elemental_depth_lookup.frag then only searches and taps.
void main() {
  const vec2 s = display_position(floor(gl_FragCoord.xy - u_region_origin) + 0.5);
  const ivec2 lens = ivec2(floor(lattice_position(s) + 0.5));
  vec2 uv;
  if (!lens_coordinate(s, lens, uv)) {
    colour = vec4(-1.0e9, -1.0e9, 0.0, 0.0);
    return;
  }
  const vec2 c = u_lattice_offset + rotate(vec2(lens) * u_lens_pitch, 1.0);
  colour = vec4(uv, c - (s - c) * u_pupil_per_lens);
}
#elif defined(NELF_COORDINATE_MAP)
// The coordinate map (one sub-sample per pixel, prefiltered view): for each pixel, where pass 1
// would tap u_view (RG), or -1 where the display is black (the prefiltered texture's clamped edge
// is black). elemental_lookup.frag then only taps: the mapping above is the same every frame,
// and on llvmpipe it cost more than the tap.
void main() {
  const vec2 s = display_position(floor(gl_FragCoord.xy - u_region_origin) + 0.5);
  vec2 uv;
  bool lit = true;
  if (u_has_lens_array == 0) {
    const vec2 r = rotate(s, -1.0);
    uv = vec2(r.x / u_view_size.x + 0.5, 0.5 - r.y / u_view_size.y);
  } else {
    lit = lens_coordinate(s, ivec2(floor(lattice_position(s) + 0.5)), uv);
  }
  colour = lit ? vec4(uv * u_texture_scale + u_texture_offset, 0.0, 1.0) : vec4(-1.0, -1.0, 0.0, 1.0);
}
#else
void main() {
  // Stratified sub-samples (1, 2×2 or 4×4). Pass 1 point-samples each; the border-strip pass
  // (border_strips.vert) area-samples each sub-aperture, splitting it between the lenses it overlaps.
  const vec2 pixel_corner = floor(gl_FragCoord.xy - u_region_origin);
  const float step_ = 1.0 / float(u_subsamples);
  vec3 sum = vec3(0.0);
  for (int sy = 0; sy < u_subsamples; ++sy) {
    for (int sx = 0; sx < u_subsamples; ++sx) {
      const vec2 centre = pixel_corner + (vec2(sx, sy) + 0.5) * step_;
#ifdef NELF_AREA_SAMPLE
      sum += area_sample(centre, step_);
#else
      sum += point_sample(centre);
#endif
    }
  }
  colour = vec4(sum * (step_ * step_), 1.0);
}
#endif
