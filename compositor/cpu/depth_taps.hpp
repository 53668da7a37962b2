#pragma once
// The taps of the depth-aware composite table (composite_table.hpp), made every frame: for each ray,
// the bilinear tap of the prefiltered image where it meets the content's surface (its flat-screen
// point moved by its gain times the crossing the search found). make_tap's rounding (each product
// in 8 bits, the largest taking the rest) in float and without branches on the data: made per pixel
// per frame, make_tap's double arithmetic and branches cost as much as the search. GL's clamp to
// edge at the image's sides (its margin is black there); any coordinate, NaN and infinities too, is
// held inside the image.
#include <array>

#include "compositor/cpu/composite_table.hpp"

namespace nelf {

// Where the rays' taps read: the prefiltered image's size (texels) and the transform from screen uv
// to its texture coordinate (uv · scale + offset).
struct DepthTapImage {
  std::array<int, 2> size{0, 0};
  std::array<float, 2> scale{1.f, 1.f}, offset{0.f, 0.f};
};

// The tap of `ray` meeting the surface at crossing `hit` (δ / W).
CompositeTable::Tap depth_tap(const CompositeTable::DepthRay& ray, float hit, const DepthTapImage& image);

// depth_tap() of `count` rays with their crossings `hits` into `out`, a black ray (u < -1e8: a black
// pixel of the display) taking `black`: eight at a time with AVX2 where the CPU has it (the same
// operations, so the same taps), one at a time elsewhere.
void depth_taps(const CompositeTable::DepthRay* rays, const float* hits, int count, const DepthTapImage& image,
                CompositeTable::Tap black, CompositeTable::Tap* out);

}  // namespace nelf
