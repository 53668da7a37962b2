#pragma once
// Frames that are already in panel space: each eye's image is what its panel must show pixel for
// pixel (the flat fields, cursor and markers of `nelf calibrate --defects`), so they skip the lens
// mapping, the overlays and the defect compensation of FrameCompositor and are only placed at the
// layout's eye origins, black elsewhere — what place_eyes does for stills.
#include "core/image.hpp"
#include "core/packed_layout.hpp"
#include "core/packed_target.hpp"

namespace nelf {

// `panels` (each layout.eye in size, values 0..1; else std::invalid_argument) into `target`: a GL
// target's texture gets the packed frame uploaded (BGRA8; its GL context must be current), a
// PackedFrame is filled (the layout's size, 8 bits a channel, RGBA). Throws gl::GlError when GL
// fails.
void render_panel_frame(const PackedLayout& layout, const EyeImages& panels, const PackedTarget& target);

}  // namespace nelf
