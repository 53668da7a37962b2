#pragma once
// The design report of a profile (`nelf design`): every figure of DESIGN.md §2, per axis where the
// model is per axis (horizontal from the display's width, vertical from its height).
//
// Which optics a profile has decides what can be computed:
//  - [lens_array]: the near-eye light field model (Eqs. 1–15).
//  - [magnifier] (stock devices): the same model with one lens whose elemental image is the whole
//    display (Eqs. 3–5): lenses = [1, 1].
//  - neither: the optics are outside the model; only the panel and the Appendix A bound (which needs
//    nothing but the panel and the viewing geometry) are reported.
#include <array>
#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "optics/optics.hpp"
#include "optics/profile.hpp"

namespace nelf {

enum class DesignOptics { lens_array, magnifier, none };

// The wavelengths (nm) at which the diffraction limit on the pixel pitch is reported: the ends and
// the middle of the visible band.
inline constexpr std::array<int, 3> kDiffractionWavelengthsNm = {390, 550, 780};

// Figures of one axis.
struct AxisDesign {
  double elemental_image_mm = 0.0;  // Δw_s (Eq. 6)
  int lenses = 0;                   // N_l (Eq. 6)
  double fov_deg = 0.0;             // α (Eq. 7, or Eq. 3 for a magnifier)
  int resolution_px = 0;            // N_p (Eq. 8, or Eq. 4)
  double eye_box_mm = 0.0;          // w_e (Eq. 9, or Eq. 5)
  optics::DepthOfField depth_of_field;
};

struct OpticalDesign {
  double lens_width_mm = 0.0;                    // w_l: lens pitch, or the magnifier's width
  double focal_mm = 0.0;                         // f
  double gap_mm = 0.0;                           // d_l (lens_array.gap_mm, else Eq. 1)
  double magnification = 0.0;                    // M (Eq. 2, or f/(f − d_l) with a fixed gap)
  std::array<AxisDesign, 2> axis;                // [horizontal, vertical]
  int views = 0;                                 // N_v for accommodation at infinity (Eq. 15)
  std::array<double, 3> diffraction_pitch_um{};  // at kDiffractionWavelengthsNm
};

struct DesignReport {
  std::string profile;      // the profile's name
  std::string description;  // its description (may be empty)
  std::string source;       // "built-in hmz-t1" or the file it was read from
  DesignOptics kind = DesignOptics::none;

  // The panel: always known.
  std::array<int, 2> panel_px{0, 0};
  Vec2 pixel_pitch_mm;
  Vec2 display_mm;  // w_s per axis

  // Viewing geometry the figures were computed for.
  double eye_relief_mm = 0.0;     // d_e
  double virtual_image_mm = 0.0;  // d_o
  double pupil_mm = 0.0;          // a

  std::optional<OpticalDesign> optics;  // nullopt when kind == none

  // Appendix A: the shortest focal length of a simple magnifier with the profile's
  // [magnifier_comparison] f-number and eye box for this display width and eye relief.
  double simple_magnifier_min_focal_mm = 0.0;
  double comparison_f_number = 0.0;
  double comparison_eye_box_mm = 0.0;
};

DesignReport design_report(const Profile& profile);

// The JSON object `nelf design --json` prints: optical figures are null when unknown, a depth of
// field that reaches infinity has a null far end. Per-axis quantities that are scalars in the
// schema (gap, magnification, elemental image, eye box, depth of field) carry the horizontal value.
nlohmann::json design_to_json(const DesignReport& report);

// The aligned, human-readable table `nelf design` prints.
std::string design_table(const DesignReport& report);

}  // namespace nelf
