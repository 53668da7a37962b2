#pragma once
// A device profile (DESIGN.md §8): one near-eye display, its optics, viewing geometry and calibration.
// Profiles are TOML files; the built-ins (`hmz-t1`, `hmz-t1-stock`) are embedded in the binary.
#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "optics/optics.hpp"

namespace nelf {

// A problem with a profile. what() is one line naming the file, the key, the value and the rule.
class ProfileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Vec2 {
  double x = 0.0;
  double y = 0.0;
  friend bool operator==(const Vec2&, const Vec2&) = default;
};

struct DisplaySpec {
  std::array<int, 2> resolution{0, 0};  // pixels of one eye's microdisplay [width, height]
  Vec2 pixel_pitch_mm;                  // per axis; from pixel_pitch_mm or size_mm / resolution
  double width_mm() const { return resolution[0] * pixel_pitch_mm.x; }
  double height_mm() const { return resolution[1] * pixel_pitch_mm.y; }
};

struct LensArraySpec {
  double pitch_mm = 0.0;         // w_l
  double focal_length_mm = 0.0;  // f
  std::optional<double> gap_mm;  // d_l; derived from Eq. 1 when absent
  double rotation_deg = 0.0;
  Vec2 offset_mm;
};

// The single lens of a stock (non-light-field) head-mounted display.
struct MagnifierSpec {
  double width_mm = 0.0;
  double focal_length_mm = 0.0;
};

struct ViewingSpec {
  double eye_relief_mm = 0.0;     // d_e
  double virtual_image_mm = 0.0;  // d_o
  double pupil_mm = 4.0;          // a
  double ipd_mm = 63.0;
};

struct ScreenSpec {
  double distance_mm = 0.0;  // d_r; 0 = virtual_image_mm
  double width_mm = 0.0;     // 0 = largest that fits both eyes' field of view
  bool converge = true;
};

struct EyeCalibration {
  Vec2 shift_px;              // the eye image moves right/down by this many pixels
  double rotation_deg = 0.0;  // added to lens_array.rotation_deg
  double pitch_scale = 1.0;   // k
};

struct DefectMap;  // optics/defect_map.hpp

struct CorrectionSpec {
  double prescription_diopters = 0.0;
  std::string defect_map;                 // as the profile gives it: relative to the profile file's directory
  std::filesystem::path defect_map_path;  // where it was read from ("" without a map)
  // The map read when the profile was loaded (null without one): validated against the panel, so
  // every command that takes a profile refuses a bad map.
  std::shared_ptr<const DefectMap> defects;
};

struct MagnifierComparison {
  double eye_box_mm = 10.0;
  double f_number = 1.0;
};

enum class Eye { left = 0, right = 1 };

struct Profile {
  std::string name;
  std::string description;
  std::string source;  // where it came from: "built-in hmz-t1" or the file path
  DisplaySpec display;
  std::optional<LensArraySpec> lens_array;  // absent = stock device
  std::optional<MagnifierSpec> magnifier;   // stock devices only
  ViewingSpec viewing;
  ScreenSpec screen;
  std::string signal = "hdmi-fp-720p60";
  std::array<EyeCalibration, 2> calibration;  // indexed by Eye
  CorrectionSpec correction;
  MagnifierComparison magnifier_comparison;

  const EyeCalibration& eye_calibration(Eye eye) const { return calibration[static_cast<int>(eye)]; }
};

// Parses and validates a profile from TOML text. `origin` names it in error messages, and is the
// file a relative correction.defect_map is found beside (the working directory for a built-in);
// the map is read and validated against the panel here.
Profile parse_profile(std::string_view toml_text, const std::string& origin);

// A built-in name (see builtin_profile_names()) or a path to a TOML file.
Profile load_profile(const std::string& name_or_path);

struct BuiltinProfileInfo {
  std::string name;
  std::string description;
};
std::vector<BuiltinProfileInfo> builtin_profiles();

// The per-axis geometry of `profile` along axis 0 (horizontal) or 1 (vertical), for its lens array
// or magnifier: what the optics of DESIGN.md §2 (optics/optics.hpp) compute from. The gap is the
// hardware's when the profile fixes it, left empty otherwise so that the optics functions apply
// Eq. 1 and Eq. 2 exactly. Throws std::logic_error when the profile has neither.
optics::AxisGeometry axis_geometry(const Profile& profile, int axis);

// Serialises a profile back to TOML (every key, explicit values) so that parse_profile reads it back equal.
std::string profile_to_toml(const Profile& profile);

}  // namespace nelf
