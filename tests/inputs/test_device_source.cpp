// The device: and v4l2: inputs (FFmpeg's capture devices through libavdevice), on the one device
// every machine has: lavfi, a filter graph read as a live device. Live: no duration, no seek, the
// newest frames as they come; interrupt() ends it; every bad name is one line.
#include <gtest/gtest.h>

#include <string>

#include "core/user_error.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/video_source.hpp"
#include "support/source_requests.hpp"

namespace nelf {
namespace {

using test::quiet_request;

const std::string kTestDevice = "device:lavfi:testsrc2=size=640x180:rate=30";

TEST(DeviceSource, ALavfiGraphIsALiveSideBySideInput) {
  quiet_ffmpeg_logs(true);
  EXPECT_EQ(source_driver_for(quiet_request(kTestDevice)).name, "device");
  EXPECT_EQ(source_driver_for(quiet_request("v4l2:/dev/video0")).name, "device");
  const auto source = open_source(quiet_request(kTestDevice));
  const SourceInfo info = source->info();
  EXPECT_TRUE(info.live);
  EXPECT_FALSE(info.seekable);
  EXPECT_FALSE(info.duration_s);
  EXPECT_FALSE(info.expected_frames);
  EXPECT_DOUBLE_EQ(info.frame_rate, 30.0);
  EXPECT_NE(info.description.find("layout sbs (aspect)"), std::string::npos) << info.description;
  EXPECT_EQ(info.view, (ViewGeometry{320, 180, 320.0 / 180.0}));
  double last = -1;
  for (int i = 0; i < 10; ++i) {
    const auto frame = source->next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->width, 320);
    EXPECT_EQ(frame->height, 180);
    if (i == 0) {
      EXPECT_NEAR(frame->pts_s, 0.0, 1e-9);
    }
    EXPECT_GT(frame->pts_s, last);
    last = frame->pts_s;
  }
  EXPECT_THROW(source->seek(1.0), UserError);
  // A device is not opened a second time for its sound.
  EXPECT_EQ(source->open_audio({}).stream, nullptr);
  EXPECT_EQ(source->open_carried_streams(), nullptr);
}

TEST(DeviceSource, InterruptEndsIt) {
  quiet_ffmpeg_logs(true);
  const auto source = open_source(quiet_request(kTestDevice));
  ASSERT_TRUE(source->next());
  source->interrupt();
  EXPECT_FALSE(source->next());
  EXPECT_FALSE(source->next());
  EXPECT_EQ(source->lost_frames(), 0) << "an interrupted device has lost nothing";
}

TEST(DeviceSource, BadNamesAreOneLineNamingTheInput) {
  quiet_ffmpeg_logs(true);
  struct Case {
    std::string input;
    int status;
    std::string expected;
    std::optional<StereoLayout> layout = std::nullopt;
    std::optional<double> start = std::nullopt;
  };
  const Case cases[] = {
      {"device:", 2, "device:: name the device as device:FORMAT:INPUT"},
      {"v4l2:", 2, "v4l2: name the device"},
      {"device:nosuch:x", 1, "device:nosuch:x: FFmpeg has no input device 'nosuch'"},
      {"device:matroska:x.mkv", 1, "FFmpeg has no input device 'matroska'"},  // a demuxer, not a device
      {"v4l2:/dev/no-such-video", 1, "v4l2:/dev/no-such-video: cannot open"},
      {kTestDevice, 2, "--start needs a file", std::nullopt, 3.0},
      {kTestDevice, 2, "layout pair needs two files", StereoLayout::pair},
  };
  for (const Case& c : cases) {
    SourceRequest r = quiet_request(c.input);
    r.layout = c.layout;
    r.start_s = c.start;
    r.right = c.layout ? "right.mkv" : "";
    try {
      open_source(r);
      ADD_FAILURE() << c.input << " opened";
    } catch (const UserError& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.status(), c.status) << what;
      EXPECT_NE(what.find(c.expected), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace nelf
