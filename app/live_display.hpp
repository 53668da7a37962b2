#pragma once
// Opening the live output of `nelf play` and `nelf calibrate`: the packed frame of the profile's
// panel under the signal, on the kind of output the user chose (hmz_output/display.hpp). Failures
// become UserError (exit 1) with the display's own one-line message.
#include <memory>
#include <string>

#include "optics/profile.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/signal.hpp"

namespace nelf::app {

struct LiveDisplayRequest {
  OutputKind kind = OutputKind::window;
  std::string monitor;    // fullscreen: a name to match ("" = the one containing "HMZ")
  std::string connector;  // kms: connector name ("" = the first with a 3D frame-packing mode)
  std::string title = "nelf";
};

std::unique_ptr<Display> open_live_display(const LiveDisplayRequest& request, const Profile& profile,
                                           const Signal& signal);

}  // namespace nelf::app
