// Choosing the fullscreen monitor and the xrandr commands offered when its mode is wrong: pure
// functions, no X server.
#include <gtest/gtest.h>

#include "hmz_output/modeline.hpp"
#include "hmz_output/monitor_selection.hpp"

namespace nelf {
namespace {

const Signal& fp720p60() {
  static const Signal signal = *find_signal("hdmi-fp-720p60");
  return signal;
}

constexpr std::array<int, 2> k720Packed{1280, 1470};

std::vector<MonitorInfo> desk_and_hmd() {
  return {{"DP-1", "DELL U2720Q", 3840, 2160, 60.0}, {"HDMI-1", "HMZ-T1", 1280, 1470, 60.0}};
}

TEST(ModeLine, Frame720p60MatchesDesignTimings) {
  EXPECT_EQ(xrandr_mode_name(*fp720p60().timing), "1280x1470_60_fp");
  EXPECT_EQ(xrandr_newmode_arguments(*fp720p60().timing),
            "\"1280x1470_60_fp\" 148.50 1280 1390 1430 1650 1470 1475 1480 1500 +hsync +vsync");
}

TEST(ModeLine, Frame720p50And1080p24) {
  EXPECT_EQ(xrandr_newmode_arguments(*find_signal("hdmi-fp-720p50")->timing),
            "\"1280x1470_50_fp\" 148.50 1280 1720 1760 1980 1470 1475 1480 1500 +hsync +vsync");
  EXPECT_EQ(xrandr_newmode_arguments(*find_signal("hdmi-fp-1080p24")->timing),
            "\"1920x2205_24_fp\" 148.50 1920 2558 2602 2750 2205 2209 2214 2250 +hsync +vsync");
}

TEST(ModeLine, NegativeSyncAndTheThreeCommands) {
  VideoTiming timing = *fp720p60().timing;
  timing.h_sync_positive = false;
  timing.v_sync_positive = false;
  const auto commands = xrandr_commands(timing, "HDMI-2");
  ASSERT_EQ(commands.size(), 3u);
  EXPECT_EQ(commands[0],
            "xrandr --newmode \"1280x1470_60_fp\" 148.50 1280 1390 1430 1650 1470 1475 1480 1500 -hsync -vsync");
  EXPECT_EQ(commands[1], "xrandr --addmode HDMI-2 1280x1470_60_fp");
  EXPECT_EQ(commands[2], "xrandr --output HDMI-2 --mode 1280x1470_60_fp");
}

TEST(MonitorSelection, DefaultFindsTheHmzByItsEdidName) {
  const auto choice = choose_monitor(desk_and_hmd(), "", k720Packed, fp720p60());
  ASSERT_TRUE(choice.index) << choice.error;
  EXPECT_EQ(*choice.index, 1u);
}

TEST(MonitorSelection, DefaultMatchesHmzInTheOutputNameCaseInsensitively) {
  const std::vector<MonitorInfo> monitors{{"eDP-1", "", 1920, 1080, 60}, {"hmz-left", "", 1280, 1470, 60}};
  const auto choice = choose_monitor(monitors, "", k720Packed, fp720p60());
  ASSERT_TRUE(choice.index) << choice.error;
  EXPECT_EQ(*choice.index, 1u);
}

TEST(MonitorSelection, NamedMonitorByOutputOrModel) {
  auto monitors = desk_and_hmd();
  monitors[0].width = 1280;
  monitors[0].height = 1470;
  EXPECT_EQ(choose_monitor(monitors, "dp-1", k720Packed, fp720p60()).index, 0u);
  EXPECT_EQ(choose_monitor(monitors, "DELL U2720Q", k720Packed, fp720p60()).index, 0u);
  EXPECT_EQ(choose_monitor(monitors, "hdmi-1", k720Packed, fp720p60()).index, 1u);
}

TEST(MonitorSelection, WholeNameWinsOverPartialMatches) {
  const std::vector<MonitorInfo> monitors{{"HDMI-10", "", 1280, 1470, 60}, {"HDMI-1", "", 1280, 1470, 60}};
  EXPECT_EQ(choose_monitor(monitors, "HDMI-1", k720Packed, fp720p60()).index, 1u);
}

TEST(MonitorSelection, SeveralPartialMatchesAreAnError) {
  const std::vector<MonitorInfo> monitors{{"HDMI-1", "HMZ-T1", 1280, 1470, 60}, {"HDMI-2", "HMZ-T2", 1280, 1470, 60}};
  const auto choice = choose_monitor(monitors, "", k720Packed, fp720p60());
  EXPECT_FALSE(choice.index);
  EXPECT_EQ(choice.error,
            "fullscreen: several monitors match \"HMZ\": HDMI-1 (HMZ-T1) 1280x1470 at 60 Hz, HDMI-2 (HMZ-T2) "
            "1280x1470 at 60 Hz; pass --monitor with a full name");
}

TEST(MonitorSelection, NoMatchListsEveryMonitorWithItsMode) {
  const std::vector<MonitorInfo> monitors{{"DP-1", "DELL U2720Q", 3840, 2160, 59.997}, {"eDP-1", "", 1920, 1200, 0}};
  const auto choice = choose_monitor(monitors, "", k720Packed, fp720p60());
  EXPECT_FALSE(choice.index);
  EXPECT_EQ(choice.error,
            "fullscreen: no monitor name contains \"HMZ\"; connected monitors: DP-1 (DELL U2720Q) 3840x2160 at 60 Hz, "
            "eDP-1 1920x1200; pass --monitor NAME");
  const auto named = choose_monitor(monitors, "HDMI-3", k720Packed, fp720p60());
  EXPECT_EQ(named.error.rfind("fullscreen: no monitor is named \"HDMI-3\"; connected monitors: DP-1", 0), 0u)
      << named.error;
}

TEST(MonitorSelection, NoMonitorsAtAll) {
  const auto choice = choose_monitor({}, "", k720Packed, fp720p60());
  EXPECT_FALSE(choice.index);
  EXPECT_EQ(choice.error, "fullscreen: the window system reports no monitors");
}

TEST(MonitorSelection, WrongModeGivesTheXrandrCommands) {
  auto monitors = desk_and_hmd();
  monitors[1].width = 1280;
  monitors[1].height = 720;
  const auto choice = choose_monitor(monitors, "", k720Packed, fp720p60());
  EXPECT_FALSE(choice.index);
  EXPECT_EQ(choice.error,
            "fullscreen: monitor HDMI-1 is in mode 1280x720, but the hdmi-fp-720p60 signal needs 1280x1470 pixels 1:1; "
            "add and select the mode with:\n"
            "  xrandr --newmode \"1280x1470_60_fp\" 148.50 1280 1390 1430 1650 1470 1475 1480 1500 +hsync +vsync\n"
            "  xrandr --addmode HDMI-1 1280x1470_60_fp\n"
            "  xrandr --output HDMI-1 --mode 1280x1470_60_fp");
}

TEST(MonitorSelection, WrongModeForASignalWithoutTimingSaysWhichSize) {
  const Signal sbs = *find_signal("sbs");
  const std::vector<MonitorInfo> monitors{{"HDMI-1", "HMZ-T1", 1280, 1470, 60}};
  const auto choice = choose_monitor(monitors, "", {2560, 720}, sbs);
  EXPECT_FALSE(choice.index);
  EXPECT_EQ(choice.error,
            "fullscreen: monitor HDMI-1 is in mode 1280x1470, but the sbs signal needs 2560x720 pixels 1:1; switch the "
            "monitor to a 2560x720 mode (xrandr --output HDMI-1 --mode 2560x720) or use --output window");
}

std::vector<unsigned char> edid_with_name(const std::string& name) {
  std::vector<unsigned char> edid(128, 0);
  const unsigned char header[8] = {0x00, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x00};
  std::copy(header, header + 8, edid.begin());
  // Descriptor 1: a detailed timing (non-zero pixel clock); descriptor 2: serial number (0xFF);
  // descriptor 3: the monitor name.
  edid[54] = 0x02;
  edid[55] = 0x3A;
  edid[72 + 3] = 0xFF;
  edid[72 + 5] = '1';
  unsigned char* d = edid.data() + 90;
  d[3] = 0xFC;
  std::size_t i = 0;
  for (; i < name.size() && i < 13; ++i) d[5 + i] = static_cast<unsigned char>(name[i]);
  if (i < 13) d[5 + i++] = 0x0A;
  for (; i < 13; ++i) d[5 + i] = 0x20;
  return edid;
}

TEST(EdidMonitorName, ReadsTheNameDescriptor) {
  EXPECT_EQ(edid_monitor_name(edid_with_name("HMZ-T1")), "HMZ-T1");
  EXPECT_EQ(edid_monitor_name(edid_with_name("ABCDEFGHIJKLM")), "ABCDEFGHIJKLM");  // 13 characters, no LF
}

TEST(EdidMonitorName, NoNameOrShortBlock) {
  auto edid = edid_with_name("HMZ-T1");
  edid[90 + 3] = 0xFE;  // unspecified text, not a name
  EXPECT_EQ(edid_monitor_name(edid), "");
  EXPECT_EQ(edid_monitor_name(std::vector<unsigned char>(100, 0)), "");
  EXPECT_EQ(edid_monitor_name({}), "");
}

}  // namespace
}  // namespace nelf
