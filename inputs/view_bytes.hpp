#pragma once
// A float RGBA view (core/image.hpp) as the bytes a StereoVideoFrame carries: what the drivers
// that make their views as images (the synthetic clip, stills) deliver.
#include <cstdint>
#include <vector>

#include "core/image.hpp"

namespace nelf {

// Tightly packed RGBA of `bits` per channel (8, or 16: native-endian uint16), clamped to 0..1 and
// rounded to the nearest code value.
std::vector<std::uint8_t> view_bytes(const Image& image, int bits);

}  // namespace nelf
