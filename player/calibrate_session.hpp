#pragma once
// The interactive part of `nelf calibrate`: a live display showing the current test pattern through
// the compositor, keys handled by CalibrationControls, each change shown briefly on screen.
#include <optional>
#include <string>

#include "compositor/compositor.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/signal.hpp"
#include "inputs/test_patterns.hpp"
#include "optics/profile.hpp"
#include "player/defect_marking.hpp"

namespace nelf {

struct CalibrateSession {
  std::string output = "window";  // a live row of hmz_output/output_drivers.cpp
  Profile profile;
  Signal signal;
  TestPattern pattern = TestPattern::stripes;
  CompositorOptions compositor;
  std::string monitor;     // fullscreen: a name to match ("" = the one containing "HMZ")
  std::string connector;   // kms: connector name ("" = the first with a 3D frame-packing mode)
  std::string save;        // .toml path written on w and at the end ("" = nowhere)
  std::optional<int> gpu;  // offscreen: the EGL device
  // --defects: flat fields on the panels without the lens mapping, starting with this one, to mark
  // dead and stuck pixels (player/defect_session.hpp); `pattern` is not shown then.
  std::optional<DefectField> defects;
};

// Runs until q/Esc, the window is closed or an interrupt (player/interrupt.hpp); saves to session.save (when given) on
// w and at the end, saying where on stdout. With session.defects, the defect-marking session
// (run_defect_session) instead. Throws UserError for a display that cannot open.
void run_calibrate_session(const CalibrateSession& session);

// Writes `profile` as TOML to `path` (replacing it, never half-written); UserError when it cannot.
void save_calibrated_profile(const Profile& profile, const std::string& path);

}  // namespace nelf
