#pragma once
// Where each eye's image lies in a packed frame, as data: made once per output by packed_layout()
// (hmz_output/packing.hpp, the one placement policy), then carried to whatever draws or copies eyes
// into the frame (the GL compositor's targets, the CPU composite tables, pack_eyes).
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "core/image.hpp"

namespace nelf {

struct EyeArea {
  int x = 0, y = 0, width = 0, height = 0;
};

struct PackedLayout {
  std::array<int, 2> packed{0, 0};  // the packed frame's size
  std::array<int, 2> eye{0, 0};     // each eye image's size (the panel)
  // Per eye ([0] left, [1] right, as nelf::Eye): the area the signal reserves for it, and where the
  // eye image's top-left corner goes, centred 1:1 in that area (cropped evenly when larger).
  // nullopt: the signal does not carry that eye.
  std::array<std::optional<EyeArea>, 2> areas;
  std::array<std::optional<std::pair<int, int>>, 2> origins;
};

// Video renders an eye only where it fits its area (GL draws the whole panel at its origin): throws
// UserError (status 2) "the WxH panel of profile P does not fit the WxH eye area of signal S",
// followed by `advice`, when an eye image is larger than the area the signal reserves for it.
void require_eyes_fit(const PackedLayout& layout, std::string_view profile_name, std::string_view signal_name,
                      std::string_view advice = {});

// The packed frame of `layout` holding `eyes` (each layout.eye in size, else std::invalid_argument):
// each eye image at its origin, clipped to its area, black (alpha 1) elsewhere. What stills are.
Image place_eyes(const PackedLayout& layout, const EyeImages& eyes);

}  // namespace nelf
