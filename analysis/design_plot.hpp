#pragma once
// The trade-space picture of `nelf design --plot` (after Lanman & Luebke, Fig. 5): spatial resolution
// N_p (Eq. 8, horizontal axis of the display) as colour over lens focal length f and lens pitch w_l,
// for the profile's display and viewing geometry, with the gap from Eq. 1 at every point.
#include <filesystem>
#include <stdexcept>

#include "optics/profile.hpp"

namespace nelf {

// A plot that could not be drawn or written. what() is one line naming the file and the cause.
class PlotError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// N_p (Eq. 8, horizontal) of a lens array of pitch `lens_pitch_mm` and focal length `focal_mm` in
// front of the profile's display, viewed from its eye relief with the image at its virtual image
// distance (gap from Eq. 1). The profile's own lens array, if any, is ignored.
int trade_space_resolution_px(const Profile& profile, double focal_mm, double lens_pitch_mm);

// Draws the plot and writes it to `path` (format from the extension, PNG intended). The file appears
// complete or not at all: it is written under a temporary name in the same directory and renamed.
// Profiles with a lens array get their design marked; others (stock devices, magnifiers, whose single
// lens is not a point of this lens-array trade space) get the plot for their panel with nothing marked.
void write_trade_space_plot(const Profile& profile, const std::filesystem::path& path);

}  // namespace nelf
