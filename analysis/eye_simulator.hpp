#pragma once
// Validation by simulating the eye (DESIGN.md §5): what a thin-lens eye sees when it looks through
// the lens array at a displayed eye image, compared with what the same eye would see looking at the
// emulated screen itself. PSNR between the two is the figure of merit.
//
// Which geometry is "physical": the simulated device is the profile's nominal hardware — [display],
// [lens_array] (pitch, focal length, gap, rotation, offset) and [viewing].eye_relief_mm — with the
// panel centred on the design pupil axis. The [calibration] section is NOT part of it: calibration
// describes how an image was rendered (to match a device whose sheet sits differently), so an image
// rendered with a calibration that does not match the nominal hardware shows up as a lower PSNR. To
// simulate hardware whose sheet really is displaced, edit the DeviceOptics (or the profile's
// lens_array) rather than the calibration.
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "core/image.hpp"
#include "optics/depth.hpp"
#include "optics/mapping.hpp"
#include "optics/profile.hpp"

namespace nelf {

// The physical optics of one eye of a lens-array device, in the per-eye coordinates of DESIGN.md §3.
struct DeviceOptics {
  std::array<int, 2> panel{0, 0};  // display resolution (pixels)
  Vec2 pixel_pitch_mm;
  double eye_relief_mm = 0;  // d_e: design pupil to lens plane
  double gap_mm = 0;         // d_l: lens plane to display
  double focal_mm = 0;       // f of every lenslet
  double lens_pitch_mm = 0;  // w_l of the physical sheet
  Vec2 lattice_offset_mm;    // centre of lens (0,0), including the half-lens centring for an even lens count
  double rotation_rad = 0;   // lattice rotation
  // The lit block of lenses (DESIGN.md §3): lens indices first_lens .. first_lens + lenses − 1 per axis.
  // The sheet itself is unbounded; lenses outside the block only show black pixels.
  std::array<int, 2> first_lens{0, 0};
  std::array<int, 2> lenses{0, 0};
};

// The nominal hardware of `eye` (see the note at the top). Throws ProfileError for a stock device
// (no lens array): the simulator models light field displays only.
DeviceOptics device_optics(const Profile& profile, Eye eye);

// The eye: a thin lens at the pupil.
struct EyeModel {
  double pupil_mm = 4.0;                                      // a
  double focus_mm = std::numeric_limits<double>::infinity();  // d_a, from the pupil; +inf = relaxed
  Vec2 offset_mm;                                             // pupil displacement from the design position
  int pupil_samples_per_axis = 7;  // stratified n×n grid mapped onto the disc: n² rays per direction
};

// Throws std::invalid_argument naming the field when the eye model is unusable.
void validate_eye_model(const EyeModel& eye);

// The retinal image grid: upright, uniform in degrees. Pixel (i, j) looks in the direction
// (left_deg + (i+½) step_deg, top_deg − (j+½) step_deg) horizontally/vertically.
struct VisualField {
  int width = 0, height = 0;
  double left_deg = 0, top_deg = 0, step_deg = 0;
};

struct SimulatorOptions {
  // Retinal samples per display pixel footprint (angle one display pixel subtends on the screen).
  // 3 resolves everything the display can show; 1 is a cheap preview (used by sweeps).
  double samples_per_footprint = 3.0;
  // Extra field around the screen's angular extent, as a fraction of that extent per side, so the
  // screen edges are visible in the pictures (they do not count for the PSNR).
  double margin = 0.05;
};

struct SimulationResult {
  Image retina;  // what the eye sees through the lens array
  Image ideal;   // what it sees looking at the emulated screen
  // Per retinal pixel, 1 where the PSNR is taken: the chief ray hits the screen and the direction lies
  // in the display's clear field (see clear_field_mask).
  std::vector<std::uint8_t> evaluated;
  double psnr_db = 0;  // over `evaluated`, RGB, peak 1.0 (+inf when identical)
  // Over every on-screen pixel, including the vignetted border of the field of view.
  double psnr_full_screen_db = 0;
  double evaluated_fraction = 0;  // evaluated pixels / on-screen pixels
};

// The real scene, when the source knows its depth (issue #15): the view taken from the pupil's
// centre and its exact disparity. A ray through the pupil at P shows the view where it meets that
// surface (optics/depth.hpp's search), so an eye focused at a plane's distance sees that plane sharp
// and the others blurred by their own defocus, as it would in front of the scene itself. Exact for
// fronto-parallel planes, except in the thin strips a near plane hides from the pupil's centre
// (there the search finds the surface the centre sees).
struct SceneDepth {
  std::shared_ptr<const DisparitySurface> surface;
  DepthGeometry geometry;
};

class EyeSimulator {
 public:
  // `rendering` is the mapping the displayed images were (or will be) composited with: it supplies the
  // emulated screen (distance, centre, size) and the pixel footprint that band-limits the ideal image.
  // `view` is the source view shown on that screen. `device` is the physical optics the eye looks through.
  EyeSimulator(DeviceOptics device, const EyeMapping& rendering, const Image& view, SimulatorOptions options = {});

  // Traces the eye through the lens array onto `displayed` (panel resolution) and onto the screen,
  // or, given `scene`, onto the real scene (the ideal an eye sees in front of it).
  SimulationResult simulate(const Image& displayed, const EyeModel& eye, const SceneDepth* scene = nullptr) const;

  // The two halves of simulate(), for callers that need only one.
  Image retina(const Image& displayed, const EyeModel& eye) const;
  Image ideal(const EyeModel& eye, const SceneDepth* scene = nullptr) const;
  // Per retinal pixel, 1 where the chief ray from the pupil's centre shows a pixel of the view that
  // `view_mask` (row-major, the view's size) marks, through the scene's surface when given, else
  // where it meets the flat screen: a region of the scene (its plane) as the eye sees it.
  std::vector<std::uint8_t> view_region_mask(const EyeModel& eye, const std::vector<std::uint8_t>& view_mask,
                                             const SceneDepth* scene = nullptr) const;
  // The retina at the listed pixels (column, row) of the field only, traced as retina() traces them:
  // for measurements that look at a few spots of the field with many pupil samples.
  std::vector<Rgba> retina_at(const Image& displayed, const EyeModel& eye,
                              const std::vector<std::array<int, 2>>& pixels) const;
  // 1 where the chief ray from the eye's pupil centre hits the emulated screen.
  std::vector<std::uint8_t> on_screen_mask(const EyeModel& eye) const;
  // 1 for the directions in which a pupil of `pupil_mm` at the design position, relaxed (the widest
  // bundle on the lens plane), looks only through lit lenses. Eq. 7's field of view is the pupil
  // centre's; towards its edge part of a real pupil's bundle goes through unlit lenses and the picture
  // darkens (vignettes). That is a property of the hardware, not of the rendering, so the figure of
  // merit leaves it out; psnr_full_screen_db keeps it. Fixed for the device and pupil size, so an eye
  // moved out of the eye box is judged over the same directions as a centred one.
  std::vector<std::uint8_t> clear_field_mask(double pupil_mm) const;

  const VisualField& field() const { return field_; }
  const DeviceOptics& device() const { return device_; }
  const Image& band_limited_view() const { return band_limited_view_; }

 private:
  struct RetinaTrace;
  void check_displayed(const Image& displayed, const EyeModel& eye) const;
  DeviceOptics device_;
  double render_distance_mm_;
  Vec2 screen_centre_mm_, screen_size_mm_;
  int view_width_ = 0, view_height_ = 0;
  Image band_limited_view_;
  VisualField field_;
  std::vector<double> tan_x_, tan_y_;  // direction tangents per column / row: no trigonometry per ray
};

// The visual field covering the screen of `rendering` as seen from the design pupil.
VisualField visual_field_for_screen(const EyeMapping& rendering, const SimulatorOptions& options);

// `view` averaged over a box of `box_uv` (texture units per axis) around each texel, black outside:
// the band limit of a display pixel's footprint on the screen.
Image box_prefilter(const Image& view, Vec2 box_uv);

// Points on a disc of diameter `diameter_mm`, centred on the origin: the centres of an n×n grid on the
// square mapped by Shirley and Chiu's concentric map (area-preserving, so the strata stay equal).
std::vector<Vec2> pupil_samples(double diameter_mm, int per_axis);

// PSNR (dB, peak 1.0) of the RGB channels over the pixels where `mask` is non-zero (all when empty).
// +inf for identical images. Throws std::invalid_argument when the sizes differ or nothing is selected.
double psnr_db(const Image& a, const Image& b, const std::vector<std::uint8_t>& mask = {});

}  // namespace nelf
