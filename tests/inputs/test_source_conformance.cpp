// The Source contract, checked for every row of the driver table (a new row is covered as soon as it
// has an input maker below; the first test fails until it has): info() agrees with what next()
// delivers, negotiate() returns the format the frames then carry, seek() works when info() says
// seekable and is refused in one line otherwise, and a bad input is one line with a non-zero status.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/user_error.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/video_source.hpp"
#include "support/image_files.hpp"
#include "support/media.hpp"
#include "support/source_requests.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::TempDir;

using test::quiet_request;

// A good input and a bad one for a driver, made in `dir`; `bad_status` is the status its error has.
struct DriverInputs {
  SourceRequest good, bad;
  int bad_status = 1;
};

const std::map<std::string, std::function<DriverInputs(const TempDir&)>>& input_makers() {
  static const std::map<std::string, std::function<DriverInputs(const TempDir&)>> makers = {
      {"synthetic",
       [](const TempDir&) {
         return DriverInputs{quiet_request("synthetic:duration=0.5,size=64x36,fps=10"),
                             quiet_request("synthetic:fps=0"), 2};
       }},
      {"device",
       [](const TempDir&) {
         return DriverInputs{quiet_request("device:lavfi:testsrc2=size=64x36:rate=10,trim=duration=1"),
                             quiet_request("device:nosuch:x"), 1};
       }},
      {"still",
       [](const TempDir& dir) {
         Image sbs = test::filled_image(64, 36, {0.7f, 0.2f, 0.1f, 1.f});
         for (int y = 0; y < 36; ++y)
           for (int x = 32; x < 64; ++x) sbs.at(x, y) = {0.1f, 0.2f, 0.7f, 1.f};
         test::write_test_image(dir / "photo.jps", sbs, 3, OIIO::TypeDesc::UINT8, "jpeg");
         test::write_file(dir / "cut.jpg", test::read_file(dir / "photo.jps").substr(0, 40));
         return DriverInputs{quiet_request((dir / "photo.jps").string()), quiet_request((dir / "cut.jpg").string()), 1};
       }},
      {"file",
       [](const TempDir& dir) {
         const auto clip = test::make_media(
             dir / "sbs.mkv", test::two_colour_input(64, 36, false, 20, 10) + " -c:v ffv1 -pix_fmt yuv420p");
         test::write_file(dir / "notes.txt", "not a video\n");
         return DriverInputs{quiet_request(clip.string(), StereoLayout::sbs),
                             quiet_request((dir / "notes.txt").string()), 1};
       }},
  };
  return makers;
}

// Live rows read an X server or a PipeWire daemon, which unit tests do not have: their contract
// (info() against the frames, no seek, one line for bad inputs) is checked against real windows in
// the window suite, tests/inputs/window/test_x11_source.cpp and (a quad-buffer game's eyes)
// test_glx_stereo_source.cpp, and against a real daemon and node in tests/cli/test_pipewire_cli.cpp.
const std::vector<std::string> kLiveRows = {"x11", "glx-stereo", "pipewire"};

std::vector<std::string> driver_names() {
  std::vector<std::string> names;
  for (const SourceDriver& driver : source_drivers())
    if (std::find(kLiveRows.begin(), kLiveRows.end(), driver.name) == kLiveRows.end()) names.emplace_back(driver.name);
  return names;
}

TEST(SourceConformance, EveryDriverHasAnInputMaker) {
  for (const std::string& name : driver_names())
    EXPECT_TRUE(input_makers().count(name))
        << "no input maker for the source driver '" << name << "': add one to tests/unit/test_source_conformance.cpp";
}

class EveryDriver : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    quiet_ffmpeg_logs(true);
    const auto maker = input_makers().find(GetParam());
    if (maker == input_makers().end()) GTEST_SKIP() << "no input maker (EveryDriverHasAnInputMaker fails)";
    inputs_ = maker->second(dir_);
    ASSERT_EQ(source_driver_for(inputs_.good).name, GetParam());
    ASSERT_EQ(source_driver_for(inputs_.bad).name, GetParam());
  }
  std::vector<StereoVideoFrame> read_all(Source& source) {
    std::vector<StereoVideoFrame> frames;
    while (auto f = source.next()) {
      frames.push_back(std::move(*f));
      if (frames.size() > 10000) break;
    }
    return frames;
  }
  TempDir dir_;
  DriverInputs inputs_;
};

TEST_P(EveryDriver, InfoAgreesWithTheFramesNextDelivers) {
  const auto source = open_source(inputs_.good);
  const SourceInfo info = source->info();
  EXPECT_GT(info.frame_rate, 0.0);
  EXPECT_FALSE(info.description.empty());
  EXPECT_EQ(std::count(info.description.begin(), info.description.end(), '\n'), 0);
  const std::vector<StereoVideoFrame> frames = read_all(*source);
  ASSERT_FALSE(frames.empty());
  if (info.expected_frames) {
    EXPECT_EQ(static_cast<long>(frames.size()), *info.expected_frames);
  }
  EXPECT_NEAR(frames.front().pts_s, 0.0, 1e-6);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const StereoVideoFrame& f = frames[i];
    SCOPED_TRACE("frame " + std::to_string(i));
    EXPECT_EQ((ViewGeometry{f.width, f.height, f.aspect}), info.view);
    EXPECT_EQ(f.bits, frames.front().bits);
    EXPECT_EQ(f.block, (std::array<int, 2>{1, 1}));  // nothing negotiated: whole views
    EXPECT_EQ(f.left.size(), static_cast<std::size_t>(f.width) * f.height * bytes_per_pixel(f.bits));
    EXPECT_EQ(f.right.size(), f.left.size());
    if (i > 0) {
      EXPECT_GT(f.pts_s, frames[i - 1].pts_s);
    }
    if (info.duration_s) {
      EXPECT_LT(f.pts_s, *info.duration_s);
    }
  }
}

TEST_P(EveryDriver, NegotiateReturnsTheFormatTheFramesThenCarry) {
  const auto source = open_source(inputs_.good);
  for (const ViewFormat wanted : {ViewFormat{{2, 2}}, ViewFormat{{4, 3}}, ViewFormat{{1, 1}}}) {
    SCOPED_TRACE(std::to_string(wanted.block[0]) + "x" + std::to_string(wanted.block[1]));
    const ViewFormat got = source->negotiate(wanted);
    EXPECT_TRUE(got == wanted || got == ViewFormat{}) << got.block[0] << "x" << got.block[1];
    // The first frame again, in the new format; a live source's next one.
    if (source->info().seekable) source->seek(0.0);
    const auto f = source->next();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->block, got.block);
    EXPECT_EQ(f->left.size(), static_cast<std::size_t>(f->width / got.block[0]) * (f->height / got.block[1]) *
                                  bytes_per_pixel(f->bits));
  }
}

TEST_P(EveryDriver, SeeksWhenSeekableElseRefusesInOneLine) {
  const auto source = open_source(inputs_.good);
  const SourceInfo info = source->info();
  if (!info.seekable) {
    try {
      source->seek(0.0);
      FAIL() << "seek() succeeded on a source that says it cannot seek";
    } catch (const UserError& e) {
      EXPECT_NE(e.status(), 0);
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
    return;
  }
  const std::vector<StereoVideoFrame> first = read_all(*source);
  ASSERT_FALSE(first.empty());
  source->seek(0.0);
  const auto again = source->next();
  ASSERT_TRUE(again);
  EXPECT_NEAR(again->pts_s, 0.0, 1e-6);
  EXPECT_EQ(again->left.size(), first.front().left.size());
  if (first.size() > 2) {
    const double middle = first[first.size() / 2].pts_s;
    source->seek(middle);
    const auto there = source->next();
    ASSERT_TRUE(there);
    EXPECT_NEAR(there->pts_s, middle, 1e-6);
  }
}

TEST_P(EveryDriver, ABadInputIsOneLineWithANonZeroStatus) {
  try {
    open_source(inputs_.bad)->next();
    FAIL() << "the bad input opened";
  } catch (const UserError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.status(), inputs_.bad_status) << what;
    EXPECT_FALSE(what.empty());
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(SourceDrivers, EveryDriver, ::testing::ValuesIn(driver_names()),
                         [](const auto& row) { return row.param; });

}  // namespace
}  // namespace nelf
