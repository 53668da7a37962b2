#pragma once
// How visible a panel's dead and stuck pixels are to the eye, with and without their compensation
// (docs/defects.md, `nelf simulate --json`'s "defects"). The eye simulator traces the retina of the
// defective display and of the same display without defects over a grid of pupil positions in the
// eye box and at the screen's accommodation and ±0.5 D; each defect is judged at its retinal spot
// (a small window around where its screen point lands).
#include <array>
#include <limits>
#include <vector>

#include "analysis/eye_simulator.hpp"
#include "core/image.hpp"
#include "optics/defect_compensation.hpp"
#include "optics/defect_map.hpp"

namespace nelf {

// What the panel shows when sent `sent` (one eye's image, panel size): each defect of `map` on `eye`
// shows what it shows (black for a dead pixel) whatever it was sent (show_defects on a copy).
Image defective_display(const DefectMap& map, Eye eye, Image sent);

// `sent` with the corrections of `plan` added: each share's pixel gets weight × (what the defect was
// sent − what it shows), the corrections all worked out from `sent` as given, each pixel clipped to
// [0, 1]: the per-frame step every output takes (compensate_defects), on a copy.
Image compensated_display(const EyeDefectPlan& plan, const Image& sent);

struct DefectSpotFigures {
  int count = 0;  // defects whose spot window lies wholly in the simulator's evaluated field from some eye position
  // Spot contrast of a defect seen from one eye position: the largest |defective − clean| / clean
  // luminance (mean of R, G, B; clean floored at contrast_floor) over its spot window. Worst and mean
  // over the defects and the eye positions.
  double worst_spot_contrast = 0;
  double mean_spot_contrast = 0;
};

struct DefectVisibility {
  DefectSpotFigures all, dead, stuck;
  // PSNR (dB, peak 1) of the defective display's retina against the clean one's over the evaluated
  // field, the squared error pooled over all eye positions; +inf when they agree.
  double defect_psnr_db = std::numeric_limits<double>::infinity();
};

struct DefectMeasurementOptions {
  int eye_box_grid = 3;  // n × n pupil positions (eye_box_pupil_positions)
  std::vector<double> accommodation_offsets_diopters{-0.5, 0.0, 0.5};  // from the screen's distance
  // Finer than the simulator's default 7: one lens's beam covers a twelfth of a 4 mm pupil, and a
  // defect's contrast is that share, so it must not hinge on how many samples fall in it.
  int pupil_samples_per_axis = 12;
  double window_footprints = 1.5;  // the spot window's half side, in display footprints on the retina
  // Clean luminance below which the contrast is taken against this instead (a spot on black has no
  // Weber contrast; a stuck pixel there still counts against a faint floor).
  double contrast_floor = 0.02;
};

// The retina of each of `displays` against that of `clean` (all panel size, what the panel shows),
// for the defects `defects` (of the simulator's eye), seen by an eye of pupil `pupil_mm`. `rendering`
// is the mapping the displays were composited with (it places the defects' screen points). One
// result per display, in order. The error is gathered at the spot windows: seen from inside the eye
// box a pixel reaches the retina only around its own screen point, so elsewhere the displays agree
// (but for light crossing to a neighbouring lens at the eye box's edge, docs/defects.md).
std::vector<DefectVisibility> measure_defect_visibility(const EyeSimulator& simulator, const EyeMapping& rendering,
                                                        const std::vector<PixelDefect>& defects, const Image& clean,
                                                        const std::vector<const Image*>& displays, double pupil_mm,
                                                        const DefectMeasurementOptions& options = {});

}  // namespace nelf
