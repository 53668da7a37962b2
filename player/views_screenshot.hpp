#pragma once
// A screenshot of the views (Ctrl+v in play): the two views of the frame on screen side by side,
// left eye's on the left, at the source's own height and each at its display aspect (a half
// side-by-side movie's views widened again), with its subtitles: a full side-by-side picture, as
// stereo viewers open one. The frames play composites are often the prefilter's block
// means, so the frame is decoded again at full resolution from the input, opened anew.
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "core/frames.hpp"
#include "inputs/source.hpp"
#include "player/subtitle_choice.hpp"

namespace nelf::playback {

// What a views screenshot needs to know of the frame on screen and how it is shown.
struct ViewsShot {
  double pts_s = 0.0;
  bool swap_eyes = false;
  // The subtitles drawn (none: no track, or hidden) and their depth.
  std::optional<SubtitleTrackRef> subtitles;
  SubtitleStereo sub_stereo = SubtitleStereo::flat;
  double sub_parallax_percent = 0.0;
};

// The first free name of `pattern` ("nelf-views{:04d}.png": 0001 to 9999) in the current folder.
// Throws std::runtime_error when all are taken.
std::string first_free_name(const std::string& pattern);

// Writes the views of `shot` into the first free nelf-viewsNNNN.png of the current folder and
// returns its name. `reopen` opens the input again (decoded at full resolution from shot.pts_s);
// null (a live input, which cannot be read again), `on_screen` is written as it is, block means
// included. 16-bit views give a 16-bit PNG. Throws std::exception saying why not (the input cannot
// seek, the folder cannot be written).
std::string write_views_screenshot(const ViewsShot& shot, const std::function<std::unique_ptr<Source>()>& reopen,
                                   const StereoVideoFrame& on_screen);

}  // namespace nelf::playback
