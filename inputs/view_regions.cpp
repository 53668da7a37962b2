#include "inputs/view_regions.hpp"

#include <fmt/format.h>
#include <cstdio>
#include <utility>

#include "core/printable.hpp"
#include "core/user_error.hpp"

namespace nelf {

ViewRegions view_regions(StereoLayout layout, int width, int height, bool swap_eyes, double frame_display_aspect) {
  const int w = width, h = height;
  if (w <= 0 || h <= 0)
    throw LayoutError(fmt::format("layout {} does not fit an empty {}x{} frame", to_string(layout), w, h));
  const double frame_aspect = frame_display_aspect > 0.0 ? frame_display_aspect : static_cast<double>(w) / h;
  ViewRegions r;
  switch (layout) {
    case StereoLayout::sbs:
    case StereoLayout::sbs_half:
      if (w % 2 != 0)
        throw LayoutError(fmt::format("layout {} does not fit a {}x{} frame: side-by-side needs an even width",
                                      to_string(layout), w, h));
      r.left = {0, 0, w / 2, h};
      r.right = {w / 2, 0, w / 2, h};
      // A full view keeps its own pixel aspect; a half view was squeezed to half width.
      r.display_aspect = layout == StereoLayout::sbs ? frame_aspect / 2 : frame_aspect;
      break;
    case StereoLayout::tab:
    case StereoLayout::tab_half:
      if (h % 2 != 0)
        throw LayoutError(fmt::format("layout {} does not fit a {}x{} frame: top-bottom needs an even height",
                                      to_string(layout), w, h));
      r.left = {0, 0, w, h / 2};
      r.right = {0, h / 2, w, h / 2};
      r.display_aspect = layout == StereoLayout::tab ? frame_aspect * 2 : frame_aspect;
      break;
    case StereoLayout::fp: {
      const auto g = frame_packed_geometry(w, h);
      if (!g)
        throw LayoutError(fmt::format(
            "layout fp does not fit a {}x{} frame: HDMI frame packing is 1280x1470 (30-line gap) or 1920x2205 "
            "(45-line gap)",
            w, h));
      r.left = {0, 0, w, g->eye_height};
      r.right = {0, g->eye_height + g->gap_rows, w, g->eye_height};
      r.display_aspect = static_cast<double>(g->width) / g->eye_height;
      break;
    }
    case StereoLayout::mono:
      r.left = r.right = {0, 0, w, h};
      r.display_aspect = frame_aspect;
      break;
    case StereoLayout::alt:
      throw LayoutError("layout alt (frame-sequential) needs a video: one frame holds only one view");
    case StereoLayout::pair:
      throw LayoutError("layout pair needs two images (the right view with --right)");
  }
  if (swap_eyes) std::swap(r.left, r.right);
  return r;
}

LivePictureViews live_picture_views(const std::string& input, std::optional<StereoLayout> layout, bool swap_eyes,
                                    int width, int height, bool quiet) {
  LayoutEvidence evidence{layout, std::nullopt, width, height, {}};
  evidence.swap_eyes = swap_eyes;
  LivePictureViews out;
  out.decision = detect_stereo_layout(evidence);
  try {
    out.regions = view_regions(out.decision.layout, width, height, out.decision.swap_eyes);
  } catch (const LayoutError& e) {
    throw UserError(fmt::format("{}: {}", printable(input), e.what()), 2);
  }
  if (!out.decision.warning.empty() && !quiet)
    fmt::print(stderr, "nelf: warning: {}: {}\n", printable(input), printable(out.decision.warning));
  return out;
}

}  // namespace nelf
