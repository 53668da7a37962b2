// AudioStream implementations: the synthetic clip's tone delivers the clip's own samples (mono at
// its rate for convert, stereo at any rate for play) on the video's timeline, and a file's audio
// opened for a source is AudioSource's, or the reason there is none in the words play reports.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "inputs/audio_source.hpp"
#include "inputs/synthetic_tone.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::make_media;
using test::TempDir;

// Every chunk of `stream`, checked to follow on without gaps from `start_s`.
std::vector<AudioChunk> drain(AudioStream& stream, double start_s = 0.0) {
  std::vector<AudioChunk> chunks;
  double expected = start_s;
  while (auto chunk = stream.next()) {
    EXPECT_EQ(chunk->channels, stream.channels());
    EXPECT_NEAR(chunk->pts_s, expected, 1e-9);
    expected = chunk->pts_s + static_cast<double>(chunk->frames()) / stream.sample_rate();
    chunks.push_back(std::move(*chunk));
  }
  return chunks;
}

// Every chunk of `stream` as it comes.
std::vector<AudioChunk> collect(AudioStream& stream) {
  std::vector<AudioChunk> chunks;
  while (auto chunk = stream.next()) chunks.push_back(std::move(*chunk));
  return chunks;
}

// Channel `c` of `chunks`, one after the other.
std::vector<float> channel(const std::vector<AudioChunk>& chunks, int c) {
  std::vector<float> out;
  for (const auto& chunk : chunks)
    for (std::size_t i = static_cast<std::size_t>(c); i < chunk.samples.size();
         i += static_cast<std::size_t>(chunk.channels))
      out.push_back(chunk.samples[i]);
  return out;
}

TEST(SyntheticTone, IsTheClipsAudioMonoAtItsRateToTheEndOfTheLastFrame) {
  const SyntheticClipSettings settings = parse_synthetic_spec("synthetic:duration=1,fps=24");
  const SyntheticClip clip(settings);
  auto tone = open_synthetic_tone(settings, 0, {});
  EXPECT_EQ(tone->sample_rate(), 48000);
  EXPECT_EQ(tone->channels(), 1);
  EXPECT_EQ(tone->description(), "synthetic tone");
  const auto samples = channel(drain(*tone), 0);
  EXPECT_EQ(samples, clip.audio(0, 48000));
}

TEST(SyntheticTone, StartsAtTheFirstFrameDeliveredAndRoundsItsEndUp) {
  // 7 fps: frames do not start on whole samples (48000 / 7 = 6857.14…).
  const SyntheticClipSettings settings = parse_synthetic_spec("synthetic:duration=1,fps=7");
  const SyntheticClip clip(settings);
  auto tone = open_synthetic_tone(settings, 3, {});
  const auto samples = channel(drain(*tone), 0);
  const std::int64_t first = 3 * 48000 / 7;          // as convert has always counted
  const std::int64_t end = (4 * 48000 + 7 - 1) / 7;  // 4 frames left, rounded up
  EXPECT_EQ(samples, clip.audio(first, static_cast<int>(end)));
}

TEST(SyntheticTone, GivesStereoAtTheRateAskedAndSeeksOnTheVideosTimeline) {
  SyntheticClipSettings settings = parse_synthetic_spec("synthetic:duration=2");
  auto tone = open_synthetic_tone(settings, 0, {44100, 2});
  EXPECT_EQ(tone->sample_rate(), 44100);
  EXPECT_EQ(tone->channels(), 2);
  settings.audio_rate = 44100;
  const SyntheticClip at_44k(settings);
  tone->seek(1.5);
  const auto chunks = drain(*tone, 1.5);
  const auto expected = at_44k.audio(std::llround(1.5 * 44100), static_cast<int>(2 * 44100 - 1.5 * 44100));
  EXPECT_EQ(channel(chunks, 0), expected);
  EXPECT_EQ(channel(chunks, 1), expected);
  tone->seek(5.0);  // past the end: nothing more
  EXPECT_FALSE(tone->next());
}

TEST(FileAudio, IsAudioSourceOnTheVideosOrigin) {
  TempDir dir;
  const auto file = make_media(dir / "tone.mkv", "-f lavfi -i sine=f=440:d=2:r=44100 -c:a flac");
  auto opened = open_file_audio(file.string(), 0.5, false, {});
  ASSERT_TRUE(opened.stream) << opened.why_not;
  EXPECT_EQ(opened.stream->sample_rate(), 48000);
  EXPECT_EQ(opened.stream->channels(), 2);
  EXPECT_EQ(opened.stream->description(), "flac");
  AudioSource direct(file.string(), AudioSourceOptions{48000, 0.5, false});
  const auto from_stream = collect(*opened.stream);
  const auto from_source = collect(direct);
  ASSERT_FALSE(from_source.empty());
  ASSERT_EQ(from_stream.size(), from_source.size());
  for (std::size_t i = 0; i < from_stream.size(); ++i) {
    EXPECT_EQ(from_stream[i].pts_s, from_source[i].pts_s);
    EXPECT_EQ(from_stream[i].samples, from_source[i].samples);
  }

  auto mono = open_file_audio(file.string(), 0.0, false, {22050, 1});
  ASSERT_TRUE(mono.stream) << mono.why_not;
  EXPECT_EQ(mono.stream->sample_rate(), 22050);
  EXPECT_EQ(mono.stream->channels(), 1);
  const auto mono_chunks = collect(*mono.stream);
  EXPECT_NEAR(static_cast<double>(channel(mono_chunks, 0).size()), 2 * 22050, 2048);
}

TEST(FileAudio, SaysWhyThereIsNoneInThePlayersWords) {
  TempDir dir;
  const auto silent = make_media(dir / "silent.mkv", "-f lavfi -i color=c=red:s=32x32:r=10:d=0.5 -c:v ffv1");
  auto none = open_file_audio(silent.string(), 0.0, false, {});
  EXPECT_FALSE(none.stream);
  EXPECT_EQ(none.why_not, "no audio stream");
  auto missing = open_file_audio((dir / "missing.mkv").string(), 0.0, false, {});
  EXPECT_FALSE(missing.stream);
  EXPECT_EQ(missing.why_not.rfind("the audio cannot be decoded (" + (dir / "missing.mkv").string() + ": ", 0), 0u)
      << missing.why_not;
}

}  // namespace
}  // namespace nelf
