// Stereo metadata: the pure mapping to nelf layouts, and reading it from real files (Matroska
// StereoMode as stream side data, the H.264 frame-packing SEI as frame side data).
#include <gtest/gtest.h>

extern "C" {
#include <libavutil/frame.h>
#include <libavutil/stereo3d.h>
}

#include <cstring>
#include <memory>
#include <string>

#include "inputs/stereo_metadata.hpp"
#include "inputs/video_source.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::make_media;
using test::TempDir;

constexpr double k16by9 = 16.0 / 9.0;

TEST(StereoMetadataMapping, SideBySideIsHalfOrFullByTheFrameAspect) {
  const StereoMetadata sbs{StereoPacking::side_by_side, false};
  EXPECT_EQ(layout_from_stereo_metadata(sbs, 1920.0 / 1080.0), (MetadataLayout{"sbs-half", false}));
  EXPECT_EQ(layout_from_stereo_metadata(sbs, 3840.0 / 1080.0), (MetadataLayout{"sbs", false}));
  EXPECT_EQ(layout_from_stereo_metadata(sbs, 2.39), (MetadataLayout{"sbs-half", false}));  // scope, half
  EXPECT_EQ(layout_from_stereo_metadata(sbs, 2 * 4.0 / 3.0), (MetadataLayout{"sbs", false}));
}

TEST(StereoMetadataMapping, TopBottomIsHalfOrFullByTheFrameAspect) {
  const StereoMetadata tab{StereoPacking::top_bottom, false};
  EXPECT_EQ(layout_from_stereo_metadata(tab, k16by9), (MetadataLayout{"tab-half", false}));
  EXPECT_EQ(layout_from_stereo_metadata(tab, 1920.0 / 2160.0), (MetadataLayout{"tab", false}));
  EXPECT_EQ(layout_from_stereo_metadata(tab, 4.0 / 3.0), (MetadataLayout{"tab-half", false}));
}

TEST(StereoMetadataMapping, InvertMeansSwapAndOtherTypesMap) {
  EXPECT_EQ(layout_from_stereo_metadata({StereoPacking::side_by_side, true}, k16by9),
            (MetadataLayout{"sbs-half", true}));
  EXPECT_EQ(layout_from_stereo_metadata({StereoPacking::top_bottom, true}, k16by9), (MetadataLayout{"tab-half", true}));
  EXPECT_EQ(layout_from_stereo_metadata({StereoPacking::frame_sequence, false}, k16by9),
            (MetadataLayout{"alt", false}));
  EXPECT_EQ(layout_from_stereo_metadata({StereoPacking::mono, false}, k16by9), (MetadataLayout{"mono", false}));
}

TEST(StereoMetadataMapping, UnsupportedPackingsSayWhatTheyAre) {
  for (auto packing : {StereoPacking::checkerboard, StereoPacking::lines, StereoPacking::columns,
                       StereoPacking::side_by_side_quincunx}) {
    try {
      layout_from_stereo_metadata({packing, false}, k16by9);
      ADD_FAILURE() << "no error for " << to_string(packing);
    } catch (const UnsupportedStereoMetadata& e) {
      EXPECT_NE(std::string(e.what()).find(to_string(packing)), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("--layout"), std::string::npos) << e.what();
    }
  }
}

// A newer FFmpeg at run time than this build's headers can store a stereo type they do not list (FFmpeg 7
// added AV_STEREO3D_UNSPEC = 8). Reading it must not load it as the enum: under UBSan (make
// test-asan) that load is a "not a valid value for type 'enum AVStereo3DType'" error. Found by
// tests/fuzz/fuzz_stereo_metadata.
TEST(StereoMetadataFromSideData, ATypeThisBuildDoesNotListIsNoMetadata) {
  std::unique_ptr<AVFrame, void (*)(AVFrame*)> frame(av_frame_alloc(), [](AVFrame* f) { av_frame_free(&f); });
  ASSERT_TRUE(frame);
  AVStereo3D* stereo = av_stereo3d_create_side_data(frame.get());
  ASSERT_NE(stereo, nullptr);
  for (const int unknown : {AV_STEREO3D_COLUMNS + 1, 1768649473}) {
    std::memcpy(&stereo->type, &unknown, sizeof unknown);
    EXPECT_FALSE(stereo_metadata_from_frame(*frame).has_value()) << unknown;
  }
  stereo->type = AV_STEREO3D_TOPBOTTOM;  // and a known one still reads
  EXPECT_EQ(stereo_metadata_from_frame(*frame), (StereoMetadata{StereoPacking::top_bottom, false}));
}

class StereoMetadataFromFile : public ::testing::Test {
 protected:
  void SetUp() override { quiet_ffmpeg_logs(true); }
  TempDir dir;
};

TEST_F(StereoMetadataFromFile, MatroskaStereoModeIsStreamMetadata) {
  const std::string input = test::two_colour_input(64, 36, false, 3);
  struct Case {
    const char* mode;
    StereoMetadata expected;
  } cases[] = {
      {"left_right", {StereoPacking::side_by_side, false}}, {"right_left", {StereoPacking::side_by_side, true}},
      {"top_bottom", {StereoPacking::top_bottom, false}},   {"bottom_top", {StereoPacking::top_bottom, true}},
      {"block_lr", {StereoPacking::frame_sequence, false}}, {"mono", {StereoPacking::mono, false}},
  };
  for (const auto& c : cases) {
    const auto path =
        make_media(dir / (std::string(c.mode) + ".mkv"), input + " -c:v ffv1 -metadata:s:v:0 stereo_mode=" + c.mode);
    VideoSource source(path.string());
    ASSERT_TRUE(source.info().stream_stereo.has_value()) << c.mode;
    EXPECT_EQ(*source.info().stream_stereo, c.expected) << c.mode;
    EXPECT_EQ(source.stereo_metadata(), c.expected) << c.mode;
  }
}

TEST_F(StereoMetadataFromFile, NoMetadataMeansNone) {
  const auto path = make_media(dir / "plain.mkv", test::two_colour_input(64, 36, false, 3) + " -c:v ffv1");
  VideoSource source(path.string());
  EXPECT_FALSE(source.info().stream_stereo.has_value());
  while (source.next_frame()) {
  }
  EXPECT_FALSE(source.stereo_metadata().has_value());
}

// libx264 writes the frame-packing SEI (3 = side by side, 4 = top bottom) with the keyframes only;
// the container says nothing, so the metadata appears only once a keyframe is decoded, and must be
// remembered for the frames in between.
void expect_sei(const TempDir& dir, int arrangement, StereoPacking expected, const char* extension) {
  const bool stacked = expected == StereoPacking::top_bottom;
  const auto path = make_media(dir / ("sei" + std::to_string(arrangement) + extension),
                               test::two_colour_input(64, 36, stacked, 6) +
                                   " -c:v libx264 -g 3 -x264-params frame-packing=" + std::to_string(arrangement));
  VideoSource source(path.string());
  EXPECT_FALSE(source.info().stream_stereo.has_value()) << "the container must not carry it: " << path;
  EXPECT_FALSE(source.stereo_metadata().has_value());
  int frames = 0, frames_with_sei = 0;
  while (auto frame = source.next_frame()) {
    ++frames;
    if (frame->stereo) {
      ++frames_with_sei;
      EXPECT_TRUE(frame->key_frame);
      EXPECT_EQ(frame->stereo->packing, expected);
    }
    ASSERT_TRUE(source.stereo_metadata().has_value()) << "forgotten after frame " << frames;
    EXPECT_EQ(source.stereo_metadata()->packing, expected);
    EXPECT_FALSE(source.stereo_metadata()->inverted);
  }
  EXPECT_EQ(frames, 6);
  EXPECT_GE(frames_with_sei, 1);
  EXPECT_LT(frames_with_sei, frames);
}

TEST_F(StereoMetadataFromFile, H264FramePackingSeiSideBySideInMp4) {
  expect_sei(dir, 3, StereoPacking::side_by_side, ".mp4");
}

TEST_F(StereoMetadataFromFile, H264FramePackingSeiTopBottomInMatroska) {
  expect_sei(dir, 4, StereoPacking::top_bottom, ".mkv");
}

}  // namespace
}  // namespace nelf
