#pragma once
// The calibration overlay of `nelf play` (key c): `nelf calibrate`'s grid pattern (lines 16 cells
// across, a yellow centre cross, the eye's letter) drawn over the movie's views, so that the eyes'
// alignment and the lens grid can be judged on the movie itself. Both the display's thread and the
// compositing worker draw it.
#include <array>
#include <cstdint>
#include <vector>

#include "core/image.hpp"

namespace nelf {

// The full-size grid `pattern` as drawn over block means of `block` pixels: per block, alpha = the
// share of its pixels the grid covers (not black), colour = their mean. Blending that over the
// block mean of the movie gives exactly the block mean of the grid drawn over the full view, so
// the lines look as they do without the reduction (at 1×1: the grid as is, alpha 0 or 1).
Image cover_grid(const Image& pattern, std::array<int, 2> block);

// `cover` (the grid, or an on-screen message: TextOverlay::cover) drawn over view bytes (RGBA,
// `bits` 8 or 16 a channel): where its alpha is 1 it replaces the view, where 0 the view shows
// through.
void draw_over(std::vector<std::uint8_t>& pixels, const Image& cover, int bits);

}  // namespace nelf
