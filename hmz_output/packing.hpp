#pragma once
// Packs the compositor's two eye images into the frame of an output signal.
#include <array>
#include <optional>
#include <stdexcept>

#include "core/image.hpp"
#include "core/packed_layout.hpp"
#include "hmz_output/signal.hpp"
#include "optics/profile.hpp"

namespace nelf {

// Where an eye's image goes in the packed frame of `signal` for eye images of `eye_w` x `eye_h`:
// the area reserved for it (HDMI: the fixed eye area; otherwise the eye size). nullopt when the
// signal does not carry that eye (left/right).
std::optional<EyeArea> eye_area(const Signal& signal, Eye eye, int eye_w, int eye_h);

// The packed frame of `signal` for eye images of `eye` size: its size, each eye's area, and each eye
// image centred 1:1 in its area (see pack_eyes). Every output places the eyes through this.
PackedLayout packed_layout(const Signal& signal, std::array<int, 2> eye);

// Both eye images must have the same, non-zero size. HDMI frame packing: left eye in rows
// [0, eye_height), black gap (RGB 0, alpha 1), right eye from row eye_height + gap_rows. When the eye
// images are not the signal's eye size (a 1280x720 panel on hdmi-fp-1080p24), each is centred 1:1 in
// its eye area with black borders, cropped symmetrically when larger: scaling would resample the
// elemental images, whose pixels must land exactly on the panel's pixels behind each lenslet.
// sbs: left | right; tab: left over right; left/right: that eye alone.
// Throws std::invalid_argument for empty or mismatched eye images.
Image pack_eyes(const Signal& signal, const Image& left, const Image& right);
inline Image pack_eyes(const Signal& signal, const EyeImages& eyes) {
  return pack_eyes(signal, eyes[static_cast<int>(Eye::left)], eyes[static_cast<int>(Eye::right)]);
}

}  // namespace nelf
