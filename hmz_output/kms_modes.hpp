#pragma once
// Choosing the connector and HDMI 1.4a frame-packing mode for `--output kms` (DESIGN.md §7): a
// pure function of what the DRM device reports, so every case is unit-tested on synthetic mode
// lists (there is no DRM device where the tests run).
//
// How the kernel presents stereo modes, once a client sets DRM_CLIENT_CAP_STEREO_3D: a 3D mode is
// a separate entry in the connector's mode list carrying the *2D* timings of its CEA format (for
// 720p60 frame packing: 1280x720, htotal 1650, vtotal 750, 74.25 MHz, vrefresh 60) plus a layout in
// the DRM_MODE_FLAG_3D_MASK bits of `flags` (DRM_MODE_FLAG_3D_FRAME_PACKING). When such a mode is
// set, the kernel doubles the CRTC timings (drm_mode_set_crtcinfo with CRTC_STEREO_DOUBLE): the
// active height becomes vdisplay + vtotal (720 + 750 = 1470) at twice the pixel clock, so the
// framebuffer to scan out is hdisplay x (vdisplay + vtotal), the left eye in rows [0, vdisplay),
// vtotal - vdisplay blank rows, the right eye below: exactly nelf's packed hdmi-fp-* frame.
// Without the client cap the kernel hides these modes altogether.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hmz_output/signal.hpp"

namespace nelf {

// One entry of a connector's mode list (the fields of drmModeModeInfo that matter here).
struct KmsMode {
  std::string name;   // e.g. "1280x720"
  int clock_khz = 0;  // pixel clock of the 2D timing
  int hdisplay = 0;
  int htotal = 0;
  int vdisplay = 0;
  int vtotal = 0;
  int vrefresh = 0;         // the kernel's rounded refresh; used when the totals are missing
  std::uint32_t flags = 0;  // DRM_MODE_FLAG_* (interlace, 3D layout in DRM_MODE_FLAG_3D_MASK)
  std::uint32_t type = 0;   // DRM_MODE_TYPE_* (preferred, driver, ...)

  // The refresh rate from the timings (59.94 for a 1000/1001 mode), else vrefresh.
  double refresh_hz() const;
  bool is_frame_packing() const;
  bool is_interlaced() const;
  // The framebuffer a frame-packing mode scans out: hdisplay x (vdisplay + vtotal).
  int packed_width() const { return hdisplay; }
  int packed_height() const { return vdisplay + vtotal; }
  // "1280x720@60 FP" (refresh with two decimals when it is not whole, e.g. "1280x720@59.94 FP").
  std::string describe() const;
};

struct KmsConnector {
  std::string name;  // "HDMI-A-1": kms_connector_name(type, type_id)
  bool connected = false;
  std::vector<KmsMode> modes;
};

// What one DRM device offers.
struct KmsDevice {
  std::string path;    // "/dev/dri/card0", for messages
  std::string driver;  // drmVersion name: "i915", "nouveau", "vc4", "nvidia-drm", "amdgpu", ...
  std::vector<KmsConnector> connectors;
};

// The connector and mode to scan out on.
struct KmsModeChoice {
  std::size_t connector_index = 0;  // into KmsDevice::connectors
  std::size_t mode_index = 0;       // into that connector's modes
  std::string connector_name;
  int packed_width = 0;  // framebuffer size
  int packed_height = 0;
  double refresh_hz = 0;
};

// Either a choice or one line saying what is missing and what to do.
struct KmsModeSelection {
  std::optional<KmsModeChoice> choice;
  std::string error;
  explicit operator bool() const { return choice.has_value(); }
};

// Two refresh rates are the same signal when they differ by at most this fraction: the NTSC
// variants (60 vs 59.94, 24 vs 23.976) differ by 0.1 %, distinct rates (24/25/30/50/60) by >= 4 %.
inline constexpr double kRefreshTolerance = 0.005;
bool same_refresh(double a, double b);

// Picks the frame-packing mode for `signal` (an hdmi-fp-* signal): on the connector named
// `wanted_connector`, or, when that is "", on the first connected connector offering one. A mode
// fits when it is flagged DRM_MODE_FLAG_3D_FRAME_PACKING, progressive, hdisplay x vdisplay is the
// signal's eye size, vtotal - vdisplay its gap rows, and its refresh the signal's (within
// kRefreshTolerance); among several the closest refresh wins, then the preferred mode, then the
// first listed.
KmsModeSelection select_kms_mode(const KmsDevice& device, const std::string& wanted_connector, const Signal& signal);

// "HDMI-A-1", "DP-2", "eDP-1": the kernel's name for a connector of DRM_MODE_CONNECTOR_* `type`.
std::string kms_connector_name(std::uint32_t type, std::uint32_t type_id);

// The nelf signal (hdmi-fp-720p60, ...) that a frame-packing mode carries, if any.
std::optional<std::string> signal_for_mode(const KmsMode& mode);

}  // namespace nelf
