#pragma once
// A subtitle as drawn for one view: what a subtitle track renders (inputs/) and the compositor's
// overlays draw into both views (compositor/overlays/subtitle_overlay) meet here.
#include <cstdint>
#include <vector>

namespace nelf {

// `width`×`height` pixels of RGBA8, premultiplied by alpha (so that drawing it is one
// multiply-add a channel), row 0 the top row: the size of the view pixels it is drawn over.
// `right_rgba`, when not empty, is what the right eye sees instead (subtitles authored per eye;
// `rgba` is then the left eye's, allocated too).
struct SubtitleBitmap {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
  std::vector<std::uint8_t> right_rgba;
  bool empty() const { return rgba.empty(); }
};

}  // namespace nelf
