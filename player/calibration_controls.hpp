#pragma once
// The keys of `nelf calibrate`, without any window: a profile being adjusted, the eye the keys act
// on and the pattern shown. apply() takes one key press and says what changed, with one line for
// the on-screen message. Every value stays within the profile's validation rules and the geometry
// must still work (the screen fits the field of view, and at least min_lit_fraction of each eye's
// panel still shows it), so a saved profile always loads and shows a picture.
//
// Which key does what is the calibrate rows of player/key_bindings.cpp; the README's table and the
// help lines are made from them.
#include <filesystem>
#include <string>
#include <vector>

#include "core/keys.hpp"
#include "inputs/test_patterns.hpp"
#include "optics/profile.hpp"

namespace nelf {

enum class CalibrationEye { both, left, right };
std::string calibration_eye_name(CalibrationEye eye);  // "both eyes", "left eye", "right eye"

// The name of a profile saved by `nelf calibrate --save PATH`: the file's stem ("my-hmz" for
// my-hmz.toml), so that the saved file is never taken for the profile it started from;
// "<stem>-calibrated" when the stem is a built-in profile's name.
std::string calibrated_profile_name(const std::filesystem::path& save_path);

struct CalibrationStep {
  bool profile_changed = false;  // re-render with profile()
  bool pattern_changed = false;  // re-render with pattern()
  bool save = false;             // write the profile now (w)
  bool quit = false;             // q / Esc
  bool help = false;             // show help_lines()
  std::string message;           // one line for the screen (ASCII), empty for nothing to say
};

class CalibrationControls {
 public:
  // `content_aspect`: the display aspect of the patterns, for checking that the screen still fits.
  // Throws ProfileError when `profile`'s geometry does not work to begin with.
  CalibrationControls(Profile profile, TestPattern pattern, double content_aspect = 16.0 / 9.0);

  CalibrationStep apply(const KeyPress& key);

  const Profile& profile() const { return profile_; }
  CalibrationEye selected_eye() const { return eye_; }
  TestPattern pattern() const { return pattern_; }

  static const std::vector<std::string>& help_lines();

  // Step sizes (also the README's).
  static constexpr double shift_step_px = 1.0, fine_shift_step_px = 0.1;
  static constexpr double rotation_step_deg = 0.05;
  static constexpr double pitch_scale_step = 0.0005;
  static constexpr double gap_step_mm = 0.005;
  static constexpr double ipd_step_mm = 0.5;
  static constexpr double prescription_step_diopters = 0.25;
  // A change that leaves less than this fraction of either eye's panel showing the screen (the
  // rest black) is refused, unless it shows more than before. See lit_fraction (mapping.hpp).
  // hmz-t1 lights 44% uncorrected; a myopic prescription pulls the screen in and shrinks it: 17%
  // at -4 D, 10% at -5 D, nothing at -8.25 D. 15% stops it at -4.25 D, a screen still a good
  // half of the field of view wide.
  static constexpr double min_lit_fraction = 0.15;

  // The smaller of the two eyes' lit fractions for the current profile.
  double lit_fraction() const { return lit_fraction_; }

 private:
  CalibrationStep shift(double dx, double dy);
  CalibrationStep rotate(double delta);
  CalibrationStep scale_pitch(double delta);
  CalibrationStep change_gap(double delta);
  CalibrationStep change_ipd(double delta);
  CalibrationStep change_prescription(double delta);
  // Takes `candidate` when it loads and its geometry works; otherwise keeps the current profile
  // and says why.
  CalibrationStep accept(const Profile& candidate, std::string message);
  std::vector<Eye> selected() const;

  Profile profile_;
  TestPattern pattern_;
  double content_aspect_;
  CalibrationEye eye_ = CalibrationEye::both;
  double lit_fraction_ = 0.0;
};

}  // namespace nelf
