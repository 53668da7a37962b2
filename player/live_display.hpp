#pragma once
// Opening the live output of `nelf play` and `nelf calibrate`: the packed frame of the profile's
// panel under the signal, on the kind of output the user chose (hmz_output/display.hpp). Failures
// become UserError (exit 1) with the display's own one-line message.
#include <memory>
#include <optional>
#include <string>

#include "hmz_output/display.hpp"
#include "hmz_output/signal.hpp"
#include "optics/profile.hpp"

namespace nelf {

struct LiveDisplayRequest {
  std::string output = "window";  // a live row of hmz_output/output_drivers.cpp
  std::string monitor;            // fullscreen: a name to match ("" = the one containing "HMZ")
  std::string connector;          // kms: connector name ("" = the first with a 3D frame-packing mode)
  std::string title = "nelf";
  std::optional<int> gpu;        // offscreen only
  bool keys_from_stdin = false;  // offscreen only: DisplayOptions::keys_from_stdin
};

std::unique_ptr<Display> open_live_display(const LiveDisplayRequest& request, const Profile& profile,
                                           const Signal& signal);

}  // namespace nelf
