// Connector and mode selection for --output kms on synthetic mode lists shaped like the kernel's:
// with DRM_CLIENT_CAP_STEREO_3D a 3D mode is its own entry with the 2D CEA timing and the layout
// in DRM_MODE_FLAG_3D_MASK.
#include <gtest/gtest.h>
#include <xf86drmMode.h>

#include "hmz_output/kms_modes.hpp"

namespace nelf {
namespace {

Signal signal(const char* name) {
  auto s = find_signal(name);
  if (!s) throw std::runtime_error(std::string("no signal ") + name);
  return *s;
}

KmsMode mode(int w, int h, int htotal, int vtotal, int clock_khz, std::uint32_t flags = 0, std::uint32_t type = 0) {
  KmsMode m;
  m.name = std::to_string(w) + "x" + std::to_string(h);
  m.clock_khz = clock_khz;
  m.hdisplay = w;
  m.htotal = htotal;
  m.vdisplay = h;
  m.vtotal = vtotal;
  m.vrefresh = static_cast<int>(clock_khz * 1000.0 / (htotal * vtotal) + 0.5);
  m.flags = flags | DRM_MODE_FLAG_PHSYNC | DRM_MODE_FLAG_PVSYNC;
  m.type = type | DRM_MODE_TYPE_DRIVER;
  return m;
}

constexpr std::uint32_t kFP = DRM_MODE_FLAG_3D_FRAME_PACKING;
// CEA timings (2D) as the kernel lists them.
KmsMode m1080p60(std::uint32_t f = 0) { return mode(1920, 1080, 2200, 1125, 148500, f); }
KmsMode m720p60(std::uint32_t f = 0) { return mode(1280, 720, 1650, 750, 74250, f); }
KmsMode m720p5994(std::uint32_t f = 0) { return mode(1280, 720, 1650, 750, 74176, f); }
KmsMode m720p50(std::uint32_t f = 0) { return mode(1280, 720, 1980, 750, 74250, f); }
KmsMode m1080p24(std::uint32_t f = 0) { return mode(1920, 1080, 2750, 1125, 74250, f); }
KmsMode m1080i60(std::uint32_t f = 0) { return mode(1920, 1080, 2200, 1125, 74250, f | DRM_MODE_FLAG_INTERLACE); }

KmsConnector connector(std::string name, bool connected, std::vector<KmsMode> modes) {
  return KmsConnector{std::move(name), connected, std::move(modes)};
}

KmsDevice device(std::vector<KmsConnector> connectors, std::string driver = "i915") {
  return KmsDevice{"/dev/dri/card0", std::move(driver), std::move(connectors)};
}

// An HMZ-T1-like EDID: 2D modes plus the HDMI 1.4a mandatory 3D formats.
std::vector<KmsMode> hmz_modes() {
  return {m720p60(),    m1080p24(),   m1080i60(),    m720p50(),     m1080p24(kFP),
          m720p60(kFP), m720p50(kFP), m1080i60(kFP), m720p5994(kFP)};
}

TEST(KmsModes, ConnectorNamesAreTheKernels) {
  EXPECT_EQ(kms_connector_name(DRM_MODE_CONNECTOR_HDMIA, 1), "HDMI-A-1");
  EXPECT_EQ(kms_connector_name(DRM_MODE_CONNECTOR_HDMIB, 2), "HDMI-B-2");
  EXPECT_EQ(kms_connector_name(DRM_MODE_CONNECTOR_DisplayPort, 3), "DP-3");
  EXPECT_EQ(kms_connector_name(DRM_MODE_CONNECTOR_eDP, 1), "eDP-1");
}

TEST(KmsModes, RefreshComesFromTheTimings) {
  EXPECT_NEAR(m720p60().refresh_hz(), 60.0, 1e-9);
  EXPECT_NEAR(m720p5994().refresh_hz(), 59.94, 0.001);
  EXPECT_NEAR(m1080p24().refresh_hz(), 24.0, 1e-9);
  KmsMode no_totals = m720p50();
  no_totals.htotal = 0;
  EXPECT_EQ(no_totals.refresh_hz(), 50.0);  // falls back to vrefresh
  EXPECT_TRUE(same_refresh(60.0, 59.94));
  EXPECT_TRUE(same_refresh(24.0, 23.976));
  EXPECT_FALSE(same_refresh(60.0, 50.0));
  EXPECT_FALSE(same_refresh(24.0, 25.0));
  EXPECT_FALSE(same_refresh(30.0, 29.0));
  EXPECT_EQ(m720p60(kFP).describe(), "1280x720@60 FP");
  EXPECT_EQ(m720p5994(kFP).describe(), "1280x720@59.94 FP");
  EXPECT_EQ(m1080i60().describe(), "1920x1080i@60");
}

TEST(KmsModes, FramePackedFrameIsActivePlusTotalLines) {
  // drm_mode_set_crtcinfo with CRTC_STEREO_DOUBLE: vdisplay + vtotal active lines.
  EXPECT_EQ(m720p60(kFP).packed_width(), 1280);
  EXPECT_EQ(m720p60(kFP).packed_height(), 1470);
  EXPECT_EQ(m1080p24(kFP).packed_height(), 2205);
  EXPECT_EQ(m720p60(kFP).packed_height(), signal("hdmi-fp-720p60").packed_height(0));
  EXPECT_EQ(m1080p24(kFP).packed_height(), signal("hdmi-fp-1080p24").packed_height(0));
}

TEST(KmsModes, SignalForMode) {
  EXPECT_EQ(signal_for_mode(m720p60(kFP)), "hdmi-fp-720p60");
  EXPECT_EQ(signal_for_mode(m720p5994(kFP)), "hdmi-fp-720p60");
  EXPECT_EQ(signal_for_mode(m720p50(kFP)), "hdmi-fp-720p50");
  EXPECT_EQ(signal_for_mode(m1080p24(kFP)), "hdmi-fp-1080p24");
  EXPECT_FALSE(signal_for_mode(m720p60()));      // 2D
  EXPECT_FALSE(signal_for_mode(m1080i60(kFP)));  // interlaced
  EXPECT_FALSE(signal_for_mode(m1080p60(kFP)));  // no such nelf signal
}

TEST(KmsModes, PicksTheFramePackingModeOfTheSignalOnTheFirstConnectedConnector) {
  const KmsDevice d = device({connector("DP-1", false, {m1080p60()}), connector("eDP-1", true, {m1080p60()}),
                              connector("HDMI-A-1", true, hmz_modes())});
  const KmsModeSelection s = select_kms_mode(d, "", signal("hdmi-fp-720p60"));
  ASSERT_TRUE(s) << s.error;
  EXPECT_EQ(s.choice->connector_index, 2u);
  EXPECT_EQ(s.choice->connector_name, "HDMI-A-1");
  EXPECT_EQ(s.choice->mode_index, 5u);  // the 60 Hz one, not 59.94
  EXPECT_EQ(s.choice->packed_width, 1280);
  EXPECT_EQ(s.choice->packed_height, 1470);
  EXPECT_NEAR(s.choice->refresh_hz, 60.0, 1e-9);

  const KmsModeSelection s24 = select_kms_mode(d, "", signal("hdmi-fp-1080p24"));
  ASSERT_TRUE(s24) << s24.error;
  EXPECT_EQ(s24.choice->mode_index, 4u);
  EXPECT_EQ(s24.choice->packed_width, 1920);
  EXPECT_EQ(s24.choice->packed_height, 2205);

  const KmsModeSelection s50 = select_kms_mode(d, "HDMI-A-1", signal("hdmi-fp-720p50"));
  ASSERT_TRUE(s50) << s50.error;
  EXPECT_EQ(s50.choice->mode_index, 6u);
  EXPECT_NEAR(s50.choice->refresh_hz, 50.0, 1e-9);
}

TEST(KmsModes, AcceptsTheNtscRateAndPrefersTheExactOne) {
  const auto only_5994 = device({connector("HDMI-A-1", true, {m720p60(), m720p5994(kFP)})});
  const KmsModeSelection a = select_kms_mode(only_5994, "", signal("hdmi-fp-720p60"));
  ASSERT_TRUE(a) << a.error;
  EXPECT_EQ(a.choice->mode_index, 1u);
  EXPECT_NEAR(a.choice->refresh_hz, 59.94, 0.001);

  // Either order: 60 wins over 59.94.
  for (const bool exact_first : {true, false}) {
    std::vector<KmsMode> modes = exact_first ? std::vector<KmsMode>{m720p60(kFP), m720p5994(kFP)}
                                             : std::vector<KmsMode>{m720p5994(kFP), m720p60(kFP)};
    const KmsModeSelection b =
        select_kms_mode(device({connector("HDMI-A-1", true, modes)}), "", signal("hdmi-fp-720p60"));
    ASSERT_TRUE(b) << b.error;
    EXPECT_EQ(b.choice->mode_index, exact_first ? 0u : 1u);
  }

  // Equal refresh: the preferred mode wins over the first.
  KmsMode preferred = m720p60(kFP);
  preferred.type |= DRM_MODE_TYPE_PREFERRED;
  const KmsModeSelection c =
      select_kms_mode(device({connector("HDMI-A-1", true, {m720p60(kFP), preferred})}), "", signal("hdmi-fp-720p60"));
  ASSERT_TRUE(c) << c.error;
  EXPECT_EQ(c.choice->mode_index, 1u);
}

TEST(KmsModes, SkipsConnectedConnectorsWithoutAFittingMode) {
  const KmsDevice d = device({connector("HDMI-A-1", true, {m1080p60(), m720p60()}),
                              connector("HDMI-A-2", true, {m720p50(kFP)}), connector("HDMI-A-3", true, hmz_modes())});
  const KmsModeSelection s = select_kms_mode(d, "", signal("hdmi-fp-720p60"));
  ASSERT_TRUE(s) << s.error;
  EXPECT_EQ(s.choice->connector_name, "HDMI-A-3");
}

TEST(KmsModes, IgnoresOtherLayoutsInterlacedAndWrongGaps) {
  KmsMode wrong_gap = m720p60(kFP);
  wrong_gap.vtotal = 760;  // packs 1480 rows, not the signal's 1470
  wrong_gap.clock_khz = 75240;
  const KmsDevice d = device({connector("HDMI-A-1", true,
                                        {m720p60(DRM_MODE_FLAG_3D_TOP_AND_BOTTOM),
                                         m720p60(DRM_MODE_FLAG_3D_SIDE_BY_SIDE_HALF), m1080i60(kFP), wrong_gap})});
  const KmsModeSelection s = select_kms_mode(d, "", signal("hdmi-fp-720p60"));
  ASSERT_FALSE(s);
  // The wrong-gap mode is frame packing, so the message lists what there is.
  EXPECT_NE(s.error.find("offers 3D frame packing only as"), std::string::npos) << s.error;
  EXPECT_NE(s.error.find("1920x1080i@60 FP"), std::string::npos) << s.error;
}

TEST(KmsModes, ErrorNoConnectedConnector) {
  const KmsDevice d = device({connector("HDMI-A-1", false, {}), connector("DP-1", false, {})});
  const KmsModeSelection s = select_kms_mode(d, "", signal("hdmi-fp-720p60"));
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error,
            "no display connected to /dev/dri/card0 (i915) (connectors: HDMI-A-1 (disconnected), DP-1 "
            "(disconnected)): plug the HMD in and switch it on");
}

TEST(KmsModes, ErrorNoConnectorsAtAll) {
  const KmsModeSelection s = select_kms_mode(device({}, "v3d"), "", signal("hdmi-fp-720p60"));
  ASSERT_FALSE(s);
  EXPECT_NE(s.error.find("/dev/dri/card0 (v3d) has no display connectors"), std::string::npos) << s.error;
  EXPECT_NE(s.error.find("--output window"), std::string::npos) << s.error;
}

TEST(KmsModes, ErrorNamedConnectorNotFoundListsTheOthers) {
  const KmsDevice d = device({connector("HDMI-A-1", true, hmz_modes()), connector("DP-1", false, {})});
  const KmsModeSelection s = select_kms_mode(d, "HDMI-A-2", signal("hdmi-fp-720p60"));
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error,
            "connector 'HDMI-A-2' not found on /dev/dri/card0 (i915); it has HDMI-A-1 (connected), DP-1 "
            "(disconnected)");
}

TEST(KmsModes, ErrorNamedConnectorDisconnected) {
  const KmsDevice d = device({connector("HDMI-A-1", false, {}), connector("DP-1", true, {m1080p60()})});
  const KmsModeSelection s = select_kms_mode(d, "HDMI-A-1", signal("hdmi-fp-720p60"));
  ASSERT_FALSE(s);
  EXPECT_NE(s.error.find("connector HDMI-A-1 on /dev/dri/card0 (i915) is not connected"), std::string::npos) << s.error;
}

TEST(KmsModes, ErrorNoStereoModesNamesTheDrivers) {
  const std::vector<KmsMode> flat = {m1080p60(), m720p60(), m720p50()};
  for (const char* driver : {"nvidia-drm", "amdgpu"}) {
    const KmsModeSelection s =
        select_kms_mode(device({connector("HDMI-A-1", true, flat)}, driver), "", signal("hdmi-fp-720p60"));
    ASSERT_FALSE(s);
    EXPECT_NE(s.error.find("no connected display offers a 3D frame-packing mode (HDMI-A-1: 3 2D modes)"),
              std::string::npos)
        << s.error;
    EXPECT_NE(s.error.find(std::string("driver ") + driver + " exposes no HDMI stereo modes"), std::string::npos)
        << s.error;
    EXPECT_NE(s.error.find("i915, nouveau and vc4 do; nvidia-drm and mainline amdgpu do not"), std::string::npos)
        << s.error;
  }
  // On a driver that does expose them, the monitor is the suspect.
  const KmsModeSelection named =
      select_kms_mode(device({connector("HDMI-A-1", true, flat)}, "i915"), "HDMI-A-1", signal("hdmi-fp-720p60"));
  ASSERT_FALSE(named);
  EXPECT_NE(named.error.find("HDMI-A-1 offers no 3D frame-packing modes (3 2D modes)"), std::string::npos)
      << named.error;
  EXPECT_NE(named.error.find("EDID"), std::string::npos) << named.error;
  EXPECT_NE(named.error.find("driver i915 does not expose"), std::string::npos) << named.error;
}

TEST(KmsModes, ErrorWrongFramePackingModesSuggestsTheSignal) {
  const KmsDevice d = device({connector("HDMI-A-1", true, {m720p60(), m1080p24(kFP), m720p50(kFP), m1080p24(kFP)})});
  const KmsModeSelection s = select_kms_mode(d, "", signal("hdmi-fp-720p60"));
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error,
            "HDMI-A-1 offers 3D frame packing only as 1920x1080@24 FP (hdmi-fp-1080p24), 1280x720@50 FP "
            "(hdmi-fp-720p50), not the signal's 1280x720@60 FP (hdmi-fp-720p60): use a profile whose [output] "
            "signal is \"hdmi-fp-1080p24\" or \"hdmi-fp-720p50\" (--profile FILE)");
  // Named connector: same message.
  const KmsModeSelection named = select_kms_mode(d, "HDMI-A-1", signal("hdmi-fp-720p60"));
  ASSERT_FALSE(named);
  EXPECT_EQ(named.error, s.error);
}

TEST(KmsModes, ErrorSignalNotFramePacked) {
  const KmsDevice d = device({connector("HDMI-A-1", true, hmz_modes())});
  const KmsModeSelection s = select_kms_mode(d, "", signal("sbs"));
  ASSERT_FALSE(s);
  EXPECT_NE(s.error.find("signal 'sbs' is not frame-packed"), std::string::npos) << s.error;
}

}  // namespace
}  // namespace nelf
