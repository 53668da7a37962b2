#pragma once
// `--output kms` (DESIGN.md §7): the real HDMI 1.4a path on Linux without a display server. The
// DRM device is opened with DRM_CLIENT_CAP_STEREO_3D, the connector's frame-packing mode chosen by
// kms_modes, the packed frame rendered with EGL on a GBM surface of the packed size and scanned out
// with page flips on vblank; the kernel then sends the HDMI vendor InfoFrame that switches the HMD
// to 3D. Keys come from the terminal (terminal_keys).
//
// Device: the environment variable NELF_DRM_DEVICE (e.g. /dev/dri/card1), else every
// /dev/dri/card* in order until one has a connected display with a fitting mode.
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "hmz_output/display.hpp"

namespace nelf {

// Opening the KMS output failed; what() is one line saying why and what to do.
class KmsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Opens the KMS display for options.signal (an hdmi-fp-* signal) on options.connector ("" = the
// first connected one with a fitting mode). The GL context is current on the calling thread.
// Throws KmsError.
std::unique_ptr<Display> open_kms_display(const DisplayOptions& options);

// The card nodes (card0, card1, ...) in `dri_dir`, in numeric order; empty when there are none or
// the folder does not exist.
std::vector<std::filesystem::path> find_drm_cards(const std::filesystem::path& dri_dir = "/dev/dri");

// The messages of the failures that need no DRM device to reproduce, for tests and for the
// display: opening `path` failed with `error` (an errno value); the device refused to become DRM
// master or to set the mode (`error` EACCES/EPERM/EBUSY when a display server holds it).
std::string kms_open_error(const std::string& path, int error, bool from_environment);
std::string kms_master_error(const std::string& path, const std::string& what, int error);

}  // namespace nelf
