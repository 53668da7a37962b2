#pragma once
// Subtitles drawn into both views before compositing, so that they are seen in focus through the
// lenses like the movie, and at a depth: the two copies are shifted horizontally in opposite
// directions, as a 3D Blu-ray player offsets its subtitle plane.
#include <array>
#include <optional>

#include "core/frames.hpp"
#include "core/subtitle_bitmap.hpp"

namespace nelf {

// The size of the view pixels a subtitle for `frame` is drawn for: the views' full size, or the
// size of their block means when the frame carries those.
std::array<int, 2> subtitle_canvas(const StereoVideoFrame& frame);

// The horizontal shift of each eye's copy in view pixels for `parallax_percent` of a view
// `width` pixels wide: the left eye's copy moves right by it, the right eye's left.
int subtitle_shift(double parallax_percent, int width);

// The subtitles' depth either way (--sub-parallax, the keys, a remembered one), in percent of the
// view width: more pulls the two copies so far apart that the eyes no longer fuse them.
constexpr double max_sub_parallax_percent = 10.0;

// `subtitle` (subtitle_canvas(frame) in size; an empty one draws nothing) drawn over both views of
// `frame` (8 or 16 bits a channel), the left eye's copy `parallax_percent` of the view width to the
// right of the right eye's: positive puts the text in front of the screen, 0 on it. A subtitle
// authored per eye (SubtitleBitmap::right_rgba) gives each eye its own, shifted the same way. Parts shifted
// out of a view are cut off. A frame that carries its content's depth gets it with the text's in the
// text's place (the depth-aware compositor then shows the text at its own depth, not at the depth of
// what it covers). Throws std::invalid_argument when the sizes differ.
void draw_subtitles(StereoVideoFrame& frame, const SubtitleBitmap& subtitle, double parallax_percent);

// The view pixels a subtitle covers (either eye's picture, before any shift): [x0, x1) × [y0, y1).
struct SubtitleBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool operator==(const SubtitleBox&) const = default;
};
std::optional<SubtitleBox> subtitle_box(const SubtitleBitmap& subtitle);

// --sub-parallax auto: the parallax, in percent of the view width (as draw_subtitles takes it), of
// the nearest content beneath a subtitle at `box` of views `view_width`×`view_height`, from both
// views' disparity. Beneath: the box widened by as far as the two copies can move apart (half the
// largest parallax each side), so that nothing the shifted text covers is missed. Nearest: the 95th
// percentile of the known disparities there, so that a few mismatched pixels do not throw the text
// forward. Nullopt where too little of that region has a known depth (flat, occluded, unmatched).
std::optional<double> content_parallax_beneath(const StereoDisparity& disparity, const SubtitleBox& box, int view_width,
                                               int view_height);

}  // namespace nelf
