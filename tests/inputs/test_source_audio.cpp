// A source's sound and the streams it carries, as play and convert open them: a file's audio is
// AudioSource's on the video's origin, the synthetic clip's is its tone, a file carries its own
// streams and the clip none, and play's sound comes from whichever the source gives.
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "inputs/audio_source.hpp"
#include "inputs/file_carried_streams.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/synthetic_source.hpp"
#include "inputs/video_source.hpp"
#include "player/play_sound.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {
// This file's own names: its suite is compiled as one unit (tests/CMakeLists.txt).
namespace test_source_audio {

using test::ScopedEnv;

using test::make_media;
using test::TempDir;

class SourceAudioTest : public ::testing::Test {
 protected:
  void SetUp() override { quiet_ffmpeg_logs(true); }
  TempDir dir;
};

SourceRequest request_for(const std::string& input, std::optional<double> start_s = std::nullopt) {
  return SourceRequest{input, "", StereoLayout::sbs, false, start_s, true, false, kDefaultMaxPixels};
}

// Red and blue views side by side at 10 fps for 2 s, with a tone unless `audio` is false.
std::string make_clip(const TempDir& dir, bool audio = true) {
  const std::string video = "-f lavfi -i color=c=red:s=64x36:r=10 -f lavfi -i color=c=blue:s=64x36:r=10";
  if (!audio)
    return make_media(dir / "silent.mkv", video + " -filter_complex [0][1]hstack -frames:v 20 -c:v ffv1").string();
  return make_media(dir / "clip.mkv",
                    video +
                        " -f lavfi -i sine=f=440:d=2:r=44100 -filter_complex [0][1]hstack[v] -map [v] "
                        "-map 2:a -frames:v 20 -c:v ffv1 -c:a flac")
      .string();
}

std::vector<AudioChunk> collect(AudioStream& stream) {
  std::vector<AudioChunk> chunks;
  while (auto chunk = stream.next()) chunks.push_back(std::move(*chunk));
  return chunks;
}

TEST_F(SourceAudioTest, AFilesAudioIsAudioSourcesOnTheFirstFrameDelivered) {
  const auto clip = make_clip(dir);
  auto source = open_source(request_for(clip, 0.5));
  ASSERT_NEAR(source->next()->pts_s, 0.0, 1e-9);
  auto opened = source->open_audio({44100, 2});
  ASSERT_TRUE(opened.stream) << opened.why_not;
  EXPECT_EQ(opened.stream->sample_rate(), 44100);
  AudioSource direct(clip, AudioSourceOptions{44100, 0.5, false});  // the frame at 0.5 s is the first
  const auto through_source = collect(*opened.stream), from_file = collect(direct);
  ASSERT_FALSE(from_file.empty());
  ASSERT_EQ(through_source.size(), from_file.size());
  for (std::size_t i = 0; i < from_file.size(); ++i) {
    EXPECT_EQ(through_source[i].pts_s, from_file[i].pts_s);
    EXPECT_EQ(through_source[i].samples, from_file[i].samples);
  }
  // Each call opens the stream anew, from the start.
  auto again = source->open_audio({44100, 2});
  ASSERT_TRUE(again.stream);
  EXPECT_EQ(again.stream->next()->samples, from_file.front().samples);
}

TEST_F(SourceAudioTest, AFileWithoutSoundSaysSo) {
  auto source = open_source(request_for(make_clip(dir, false)));
  const auto opened = source->open_audio({});
  EXPECT_FALSE(opened.stream);
  EXPECT_EQ(opened.why_not, "no audio stream");
}

TEST_F(SourceAudioTest, TheSyntheticClipsSoundIsItsToneFromTheStartAsked) {
  auto source = open_source(request_for("synthetic:duration=2,size=32x18", 1.0));
  auto opened = source->open_audio({});
  ASSERT_TRUE(opened.stream) << opened.why_not;
  EXPECT_EQ(opened.stream->sample_rate(), 48000);
  EXPECT_EQ(opened.stream->channels(), 1);
  std::vector<float> samples;
  for (const auto& chunk : collect(*opened.stream))
    samples.insert(samples.end(), chunk.samples.begin(), chunk.samples.end());
  const SyntheticClip clip(parse_synthetic_spec("synthetic:duration=2,size=32x18"));
  EXPECT_EQ(samples, clip.audio(48000, 48000));  // the second second
  EXPECT_FALSE(source->open_carried_streams());  // nothing to copy: its sound is encoded
}

TEST_F(SourceAudioTest, AFileCarriesItsOwnStreamsFromTheFirstFrameDelivered) {
  const auto clip = make_clip(dir);
  auto source = open_source(request_for(clip, 0.5));
  auto carried = source->open_carried_streams();
  ASSERT_TRUE(carried);
  ASSERT_EQ(carried->layout().streams.size(), 1u);
  EXPECT_EQ(carried->layout().streams[0].codec->codec_id, AV_CODEC_ID_FLAC);
  auto direct = open_file_carried_streams(clip, 0.5, false);
  const std::vector<int> wanted{1};
  int count = 0;
  while (auto p = carried->next_packet(wanted, std::nullopt, std::nullopt)) {
    auto q = direct->next_packet(wanted, std::nullopt, std::nullopt);
    ASSERT_TRUE(q);
    EXPECT_EQ(p->pts, q->pts);
    EXPECT_EQ(p->size, q->size);
    ++count;
  }
  EXPECT_FALSE(direct->next_packet(wanted, std::nullopt, std::nullopt));
  EXPECT_GT(count, 5);
}

TEST_F(SourceAudioTest, PlayPlaysTheSyntheticClipsToneAndSaysWhyAFileHasNoSound) {
  ScopedEnv driver("SDL_AUDIODRIVER", "dummy");
  PlayerOptions options;
  {
    auto synthetic = open_source(request_for("synthetic:duration=1,size=32x18"));
    playback::PlaySound sound(*synthetic, options);
    EXPECT_TRUE(sound.playing()) << sound.description();
    EXPECT_EQ(sound.description().rfind("dummy, 48000 Hz", 0), 0u) << sound.description();
    sound.stop();
  }
  auto silent = open_source(request_for(make_clip(dir, false)));
  playback::PlaySound none(*silent, options);
  EXPECT_FALSE(none.playing());
  EXPECT_EQ(none.description(), "no audio stream");
  options.audio = false;
  playback::PlaySound off(*silent, options);
  EXPECT_EQ(off.description(), "--no-audio");
}

}  // namespace test_source_audio
}  // namespace
}  // namespace nelf
