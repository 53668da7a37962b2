#include "player/calibration_controls.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "optics/mapping.hpp"
#include "player/key_bindings.hpp"

namespace nelf {

namespace {

// Values move on a grid of 1e-6 so that ten steps of 0.05 are 0.5, not 0.49999999999999994, in the
// profile and in the saved file.
double quantize(double v) { return std::round(v * 1e6) / 1e6; }

// Adds `delta` within [lo, hi]; false when the value was already at that limit.
bool step_within(double& value, double delta, double lo, double hi) {
  const double next = quantize(std::clamp(value + delta, lo, hi));
  const bool moved = next != value;
  value = next;
  return moved;
}

const char* eye_key(Eye eye) { return eye == Eye::left ? "left" : "right"; }

// The smaller lit fraction of the two eyes; throws ProfileError where the geometry does not work.
double least_lit_fraction(const Profile& profile, double content_aspect) {
  double least = 1.0;
  for (Eye eye : {Eye::left, Eye::right})
    least = std::min(least, lit_fraction(make_eye_mapping(profile, eye, content_aspect)));
  return least;
}

}  // namespace

std::string calibration_eye_name(CalibrationEye eye) {
  switch (eye) {
    case CalibrationEye::both:
      return "both eyes";
    case CalibrationEye::left:
      return "left eye";
    case CalibrationEye::right:
      return "right eye";
  }
  return "both eyes";
}

std::string calibrated_profile_name(const std::filesystem::path& save_path) {
  const std::string stem = save_path.stem().string();
  for (const auto& builtin : builtin_profiles())
    if (builtin.name == stem) return stem + "-calibrated";
  return stem;
}

CalibrationControls::CalibrationControls(Profile profile, TestPattern pattern, double content_aspect)
    : profile_(std::move(profile)),
      pattern_(pattern),
      content_aspect_(content_aspect),
      lit_fraction_(least_lit_fraction(profile_, content_aspect_)) {}

const std::vector<std::string>& CalibrationControls::help_lines() {
  static const std::vector<std::string> lines = key_help(KeyScope::calibrate);
  return lines;
}

std::vector<Eye> CalibrationControls::selected() const {
  switch (eye_) {
    case CalibrationEye::left:
      return {Eye::left};
    case CalibrationEye::right:
      return {Eye::right};
    case CalibrationEye::both:
      break;
  }
  return {Eye::left, Eye::right};
}

CalibrationStep CalibrationControls::accept(const Profile& candidate, std::string message) {
  CalibrationStep step;
  double lit = 0.0;
  try {
    // What --save would write must load again, and the compositor must be able to map it.
    parse_profile(profile_to_toml(candidate), candidate.source);
    lit = least_lit_fraction(candidate, content_aspect_);
  } catch (const std::exception& e) {
    step.message = fmt::format("not changed: {}", e.what());
    return step;
  }
  // The eye must still see a picture: a myopic prescription, the IPD or a shift can shrink the
  // screen to a patch and leave the frame nearly black. Moving back towards more light is allowed.
  if (lit < min_lit_fraction && lit < lit_fraction_) {
    step.message = fmt::format("not changed: only {:.0f}% of the panel would show the screen (at least {:.0f}%)",
                               100.0 * lit, 100.0 * min_lit_fraction);
    return step;
  }
  lit_fraction_ = lit;
  profile_ = candidate;
  step.profile_changed = true;
  step.message = std::move(message);
  return step;
}

CalibrationStep CalibrationControls::shift(double dx, double dy) {
  Profile p = profile_;
  std::string message;
  bool moved = false;
  for (Eye eye : selected()) {
    Vec2& s = p.calibration[static_cast<std::size_t>(eye)].shift_px;
    const double half_w = p.display.resolution[0] / 2.0, half_h = p.display.resolution[1] / 2.0;
    moved |= step_within(s.x, dx, -half_w, half_w);
    moved |= step_within(s.y, dy, -half_h, half_h);
    message += fmt::format("{}{} shift {:.1f}, {:.1f} px", message.empty() ? "" : "; ", eye_key(eye), s.x, s.y);
  }
  if (!moved) return CalibrationStep{false, false, false, false, false, message + " (limit)"};
  return accept(p, message);
}

CalibrationStep CalibrationControls::rotate(double delta) {
  Profile p = profile_;
  std::string message;
  bool moved = false;
  for (Eye eye : selected()) {
    double& r = p.calibration[static_cast<std::size_t>(eye)].rotation_deg;
    moved |= step_within(r, delta, -180.0, 180.0);
    message += fmt::format("{}{} rotation {:+.2f} deg", message.empty() ? "" : "; ", eye_key(eye), r);
  }
  if (!moved) return CalibrationStep{false, false, false, false, false, message + " (limit)"};
  return accept(p, message);
}

CalibrationStep CalibrationControls::scale_pitch(double delta) {
  if (!profile_.lens_array)
    return CalibrationStep{false, false, false, false, false, "pitch scale: this profile has no lens array"};
  Profile p = profile_;
  std::string message;
  bool moved = false;
  for (Eye eye : selected()) {
    double& k = p.calibration[static_cast<std::size_t>(eye)].pitch_scale;
    moved |= step_within(k, delta, 0.5, 2.0);
    message += fmt::format("{}{} pitch scale {:.4f}", message.empty() ? "" : "; ", eye_key(eye), k);
  }
  if (!moved) return CalibrationStep{false, false, false, false, false, message + " (limit)"};
  return accept(p, message);
}

CalibrationStep CalibrationControls::change_gap(double delta) {
  if (!profile_.lens_array)
    return CalibrationStep{false, false, false, false, false, "lens gap: this profile has no lens array"};
  Profile p = profile_;
  // A profile that leaves the gap to Eq. 1 starts from that value.
  double gap = quantize(lens_gap_mm(p));
  const double focal = p.lens_array->focal_length_mm;
  const bool moved = step_within(gap, delta, gap_step_mm, focal - gap_step_mm);
  p.lens_array->gap_mm = gap;
  const std::string message = fmt::format("lens gap {:.3f} mm (focal length {} mm)", gap, focal);
  if (!moved) return CalibrationStep{false, false, false, false, false, message + " (limit)"};
  return accept(p, message);
}

CalibrationStep CalibrationControls::change_ipd(double delta) {
  Profile p = profile_;
  const bool moved = step_within(p.viewing.ipd_mm, delta, 40.0, 80.0);
  const std::string message = fmt::format("IPD {:.1f} mm", p.viewing.ipd_mm);
  if (!moved) return CalibrationStep{false, false, false, false, false, message + " (limit)"};
  return accept(p, message);
}

CalibrationStep CalibrationControls::change_prescription(double delta) {
  Profile p = profile_;
  double& s = p.correction.prescription_diopters;
  const bool moved = step_within(s, delta, -20.0, 20.0);
  const std::string message =
      fmt::format("prescription {:+.2f} D (screen at {:.0f} mm)", s, p.lens_array ? render_distance_mm(p) : 0.0);
  if (!moved) return CalibrationStep{false, false, false, false, false, message + " (limit)"};
  return accept(p, message);
}

CalibrationStep CalibrationControls::apply(const KeyPress& key) {
  CalibrationStep step;
  if (key.named == KeyPress::Named::none && (key.ctrl || key.alt)) {
    // Ctrl+C in the window quits as it would in the terminal; other combinations are not ours.
    step.quit = key.ctrl && (key.character == U'c' || key.character == U'q');
    return step;
  }
  const std::optional<Command> command = command_for(KeyScope::calibrate, key);
  if (!command) {
    if (key.named == KeyPress::Named::none && key.character >= 0x20 && key.character < 0x7f)
      step.message = fmt::format("key '{}' does nothing (h: help)", static_cast<char>(key.character));
    return step;
  }
  const double px = key.shift ? fine_shift_step_px : shift_step_px;
  switch (*command) {
    case Command::next_eye:
      eye_ = eye_ == CalibrationEye::both   ? CalibrationEye::left
             : eye_ == CalibrationEye::left ? CalibrationEye::right
                                            : CalibrationEye::both;
      step.message = fmt::format("adjusting {}", calibration_eye_name(eye_));
      return step;
    case Command::shift_left:
      return shift(-px, 0.0);
    case Command::shift_right:
      return shift(px, 0.0);
    case Command::shift_up:
      return shift(0.0, -px);  // shift_px moves the image down for +y
    case Command::shift_down:
      return shift(0.0, px);
    case Command::quit:
      step.quit = true;
      return step;
    case Command::rotate_less:
      return rotate(-rotation_step_deg);
    case Command::rotate_more:
      return rotate(rotation_step_deg);
    case Command::pitch_less:
      return scale_pitch(-pitch_scale_step);
    case Command::pitch_more:
      return scale_pitch(pitch_scale_step);
    case Command::gap_less:
      return change_gap(-gap_step_mm);
    case Command::gap_more:
      return change_gap(gap_step_mm);
    case Command::ipd_narrower:
      return change_ipd(-ipd_step_mm);
    case Command::ipd_wider:
      return change_ipd(ipd_step_mm);
    case Command::prescription_less:
      return change_prescription(-prescription_step_diopters);
    case Command::prescription_more:
      return change_prescription(prescription_step_diopters);
    case Command::pattern_stripes:
    case Command::pattern_grid:
    case Command::pattern_snellen:
    case Command::pattern_white: {
      const TestPattern next = *command == Command::pattern_stripes   ? TestPattern::stripes
                               : *command == Command::pattern_grid    ? TestPattern::grid
                               : *command == Command::pattern_snellen ? TestPattern::snellen
                                                                      : TestPattern::white;
      if (next == TestPattern::snellen) {
        try {
          snellen_letter_height_px(pattern_geometry(profile_), 20);
        } catch (const TestPatternError&) {
          step.message = "no Snellen chart: the screen size is unknown";
          return step;
        }
      }
      step.pattern_changed = next != pattern_;
      pattern_ = next;
      step.message = fmt::format("pattern {}", test_pattern_name(pattern_));
      return step;
    }
    case Command::save:
      step.save = true;
      return step;
    case Command::help:
      step.help = true;
      return step;
    default:
      return step;  // a play command: not bound in calibrate
  }
}

}  // namespace nelf
