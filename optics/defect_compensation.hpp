#pragma once
// Dead and stuck pixels hidden by the light field's redundancy (the paper's §5.2, docs/defects.md).
// A display pixel is one ray of a bundle: the pixels of the neighbouring elemental images that show
// the same point of the emulated screen reach the same retinal point through other parts of the
// pupil. A defect removes (dead) or adds (stuck) light on one of those rays; the other rays of its
// bundle can make up for it. The display-to-retina model is linear and does not depend on the
// content, so the shares are worked out once per profile (plan_defect_compensation) and each frame
// only adds them (compensate_defects).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/image.hpp"
#include "optics/defect_map.hpp"
#include "optics/mapping.hpp"

namespace nelf {

// One healthy pixel of a defect's ray bundle (panel coordinates of the defect's eye) and the share
// of the defect's missing light it takes: it is sent weight × (what the defect should show − what
// it shows) more, clipped to the displayable range.
struct BundleShare {
  int x = 0, y = 0;
  float weight = 0.f;
  friend bool operator==(const BundleShare&, const BundleShare&) = default;
};

struct DefectCorrection {
  PixelDefect defect;
  std::vector<BundleShare> shares;  // none: nothing can make up for it (see EyeDefectPlan)
};

// One eye's corrections, for the profile (and the content aspect) its mapping was made for.
struct EyeDefectPlan {
  Eye eye = Eye::left;
  std::array<int, 2> panel{0, 0};
  std::vector<DefectCorrection> corrections;  // the defects of this eye that need and have a correction
  int outside_lit = 0;    // defects outside the lit elemental images: they show nothing, need nothing
  int uncompensable = 0;  // defects whose bundle has no healthy pixel left: left as they are
  bool empty() const { return corrections.empty(); }
};

// What the planning assumes of the eye: the pupil positions over which the retina is kept closest
// to a defect-free display (a grid over the eye box, the pupil at each).
struct DefectPlanOptions {
  double pupil_mm = 4.0;
  int eye_box_grid = 5;  // n × n pupil positions over the eye box
};

// The corrections for the defects of `map` that belong to `mapping.eye`: per defect, a small bounded
// least-squares problem over the pupil positions (weights ≥ 0, the healthy pixels of the bundle).
// A stock device (no lens array) has no bundles: every defect is uncompensable.
EyeDefectPlan plan_defect_compensation(const EyeMapping& mapping, const DefectMap& map,
                                       const DefectPlanOptions& options = {});

// The plan's eye box (Eq. 9 with the emulated screen's distance, per axis the same: square lenses):
// the pupil-plane extent, centred on the design pupil, from which every elemental image is seen
// through its own lens. 0 for a stock device.
double eye_box_width_mm(const EyeMapping& mapping);

// The pupil centres the plan keeps the retina right for: an n × n grid over the positions where a
// pupil of `pupil_mm` lies wholly inside the eye box (a single central position when it does not
// fit). The eye simulator's defect measurement uses the same grid.
std::vector<Vec2> eye_box_pupil_positions(const EyeMapping& mapping, double pupil_mm, int per_axis);

// The candidate pixels of the ray bundle of pixel (x, y) before other defects are taken out: for
// each lit lens within two pitches of the pixel's own, the 2 × 2 pixels around where that lens's
// elemental image shows the pixel's screen point. Empty outside the lit elemental images and for a
// stock device. A defect whose pupil-plane beam no position of the eye box sees gets no correction
// and is counted neither as outside_lit nor as uncompensable.
std::vector<std::array<int, 2>> defect_bundle_pixels(const EyeMapping& mapping, int x, int y);

// The screen point (mm) whose light defect `d` takes away or adds: through its own lens for a pixel of
// the lit elemental images; for a stuck pixel outside them (sent black, showing its value), through
// the lens in front of it when that reaches the screen. Nothing otherwise (no lens array, or a defect
// no one sees: it needs nothing).
std::optional<Vec2> defect_screen_point(const EyeMapping& mapping, const PixelDefect& d);

// Per frame, in place, on one eye's composited image (panel size; the defects' own pixels are left
// as they are, the display shows what it shows there). All corrections are worked out from the
// image as it was given, so shares that meet on one pixel add up.
void compensate_defects(const EyeDefectPlan& plan, Image& eye);
// The same on an eye area of a packed frame: RGBA, 8 or 16 bits a channel, `row_bytes` apart, the
// eye's pixel (0, 0) at `rgba`.
void compensate_defects(const EyeDefectPlan& plan, std::uint8_t* rgba, int bits, std::size_t row_bytes);

// What the panel shows when sent `eye`: each defect of `map` on that eye replaced by what it shows
// (black for a dead pixel). The simulator's defective display.
void show_defects(const DefectMap& map, Eye eye, Image& eye_image);

}  // namespace nelf
