#pragma once
// The interactive part of `nelf calibrate --defects`: a live display showing flat fields on both
// panels pixel for pixel (compositor/panel_frame.hpp: no lens mapping, no defect compensation),
// keys handled by DefectMarking, a status line on the selected panel, and the defect map saved
// where defect_map_save() says.
#include "player/calibrate_session.hpp"

namespace nelf {

// Runs until q/Esc, the window is closed or an interrupt (player/interrupt.hpp); saves the map (and
// the --save profile naming it) on w and at the end, saying where on stdout, and prints each mark
// there too. Throws UserError for a display that cannot open.
void run_defect_session(const CalibrateSession& session);

}  // namespace nelf
