#pragma once
// What the charts nelf draws share (the design trade-space plot, the simulate sweep heatmap):
// the colour map and the font.
#include <array>
#include <string>

namespace nelf::chart {

using Rgb = std::array<float, 3>;

// Perceptually uniform, colour-blind safe, readable in greyscale: matplotlib's viridis, sampled at
// 0, 0.1, …, 1 (sRGB) and interpolated linearly. t is clamped to [0, 1].
Rgb viridis(double t);

// A font OpenImageIO can render with (Debian: fonts-dejavu-core, installed by install-deps.sh); the
// plain name lets OpenImageIO search its own font paths elsewhere. Labels stay ASCII: OpenImageIO
// 2.4's render_text draws a non-ASCII character such as µ as a wrong glyph.
std::string font();

}  // namespace nelf::chart
