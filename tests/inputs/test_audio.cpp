// Audio for `nelf play`: decoding and resampling a generated file (timestamps, stereo layout,
// seeking, no audio stream) and the SDL audio clock on SDL's `dummy` driver, which consumes queued
// samples in real time (SDL 2.26: it waits one buffer period per buffer), so the clock must advance
// at the rate of the wall clock, freeze when paused and restart after a flush.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <thread>

#include "hmz_output/audio_output.hpp"
#include "inputs/audio_source.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::ScopedEnv;

using test::make_media;
using test::TempDir;

TEST(AudioSource, DecodesMonoToInterleavedStereoAtTheOutputRateWithTimestamps) {
  TempDir dir;
  // 1 s of a 1 kHz tone at 44.1 kHz mono in AAC, with a video stream as players meet it.
  const auto file = make_media(dir / "tone.mp4",
                               "-f lavfi -i color=c=gray:s=64x36:r=10:d=1 -f lavfi -i sine=f=1000:d=1:r=44100 "
                               "-c:v libx264 -preset ultrafast -c:a aac -shortest");
  AudioSource source(file.string(), AudioSourceOptions{48000, 0.0, false});
  EXPECT_EQ(source.sample_rate(), 48000);
  std::int64_t frames = 0;
  double first_pts = -1, expected_next = 0;
  double peak_left = 0, max_channel_difference = 0;
  while (auto chunk = source.next()) {
    if (first_pts < 0) first_pts = chunk->pts_s;
    // Each chunk continues where the previous one ended (within a sample or two).
    if (frames > 0) {
      EXPECT_NEAR(chunk->pts_s, expected_next, 3.0 / 48000);
    }
    expected_next = chunk->pts_s + static_cast<double>(chunk->frames()) / 48000;
    for (std::int64_t i = 0; i < chunk->frames(); ++i) {
      peak_left = std::max(peak_left, static_cast<double>(std::abs(chunk->samples[2 * i])));
      max_channel_difference = std::max(
          max_channel_difference, static_cast<double>(std::abs(chunk->samples[2 * i] - chunk->samples[2 * i + 1])));
    }
    frames += chunk->frames();
  }
  EXPECT_NEAR(first_pts, 0.0, 0.03);
  EXPECT_NEAR(static_cast<double>(frames) / 48000, 1.0, 0.05);
  EXPECT_GT(peak_left, 0.05);               // the tone is there
  EXPECT_LT(max_channel_difference, 1e-4);  // mono goes to both channels
  EXPECT_EQ(source.decode_errors(), 0);
}

TEST(AudioSource, SeekStartsAtTheRequestedTime) {
  TempDir dir;
  const auto file = make_media(dir / "tone.mka", "-f lavfi -i sine=f=440:d=3:r=48000 -c:a flac");
  AudioSource source(file.string());
  source.seek(2.0);
  auto chunk = source.next();
  ASSERT_TRUE(chunk);
  EXPECT_NEAR(chunk->pts_s, 2.0, 1.0 / 48000 + 1e-9);
  std::int64_t frames = chunk->frames();
  while (auto c = source.next()) frames += c->frames();
  EXPECT_NEAR(static_cast<double>(frames) / 48000, 1.0, 0.02);
  source.seek(0.0);  // back to the start works too
  chunk = source.next();
  ASSERT_TRUE(chunk);
  EXPECT_NEAR(chunk->pts_s, 0.0, 1e-3);
}

TEST(AudioSource, AFileWithoutSoundSaysSo) {
  TempDir dir;
  const auto file = make_media(dir / "silent.mp4", "-f lavfi -i color=c=gray:s=64x36:r=10:d=0.5 -c:v libx264");
  EXPECT_FALSE(AudioSource::has_audio(file.string()));
  try {
    AudioSource source(file.string());
    FAIL() << "no exception";
  } catch (const AudioError& e) {
    EXPECT_NE(std::string(e.what()).find("no audio stream"), std::string::npos) << e.what();
  }
}

TEST(AudioSource, NetworkProtocolsAreRefusedByDefault) {
  EXPECT_THROW(AudioSource("http://127.0.0.1:9/a.mp3"), AudioError);
}

// Interleaved stereo silence of `seconds` with timestamp `pts`.
AudioChunk silence(double pts, double seconds, int rate) {
  return AudioChunk{pts, std::vector<float>(static_cast<std::size_t>(std::lround(seconds * rate)) * 2, 0.f)};
}

double wall_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

TEST(AudioOutput, TheDummyDriverClockFollowsTheWallClockPausesAndRestarts) {
  ScopedEnv driver("SDL_AUDIODRIVER", "dummy");
  std::string why;
  auto out = AudioOutput::open(48000, why);
  ASSERT_TRUE(out) << why;
  EXPECT_EQ(out->sample_rate(), 48000);
  out->queue(silence(5.0, 2.0, 48000));
  EXPECT_TRUE(out->paused());
  EXPECT_NEAR(out->now(), 5.0, 0.03);  // nothing heard yet
  const auto start = std::chrono::steady_clock::now();
  out->set_paused(false);
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  const double played = out->now() - 5.0, buffered = out->buffered_s(), wall = wall_since(start);
  // Real-time consumption: the clock moved about as far as the wall clock. SDL's thread can only
  // fall behind on a loaded machine, never run ahead; a driver that swallowed the queue at once
  // would put the clock 2 s ahead, one that never consumed it would leave it at 5.0.
  EXPECT_GT(played, 0.2) << "after " << wall << " s";
  EXPECT_LT(played, wall + 0.03) << "after " << wall << " s";
  EXPECT_GT(buffered, 2.0 - wall - 0.05);
  EXPECT_LT(buffered, 1.85);

  out->set_paused(true);
  const double at_pause = out->now();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_NEAR(out->now(), at_pause, 0.002);

  out->restart_at(20.0);  // a seek: queue flushed, clock held at the target
  EXPECT_NEAR(out->now(), 20.0, 1e-9);
  EXPECT_EQ(out->buffered_s(), 0.0);
  out->queue(silence(20.0, 0.5, 48000));
  const auto resumed = std::chrono::steady_clock::now();
  out->set_paused(false);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const double after_restart = out->now();
  EXPECT_GT(after_restart, 20.08);
  EXPECT_LT(after_restart, 20.0 + wall_since(resumed) + 0.03);
}

TEST(AudioOutput, AfterTheLastSampleTheClockGoesOnWithTheSystemClock) {
  ScopedEnv driver("SDL_AUDIODRIVER", "dummy");
  std::string why;
  auto out = AudioOutput::open(48000, why);
  ASSERT_TRUE(out) << why;
  out->queue(silence(0.0, 0.1, 48000));
  out->end_of_stream();
  const auto start = std::chrono::steady_clock::now();
  out->set_paused(false);
  // The player reads the clock every refresh; the hand-over to the system clock happens at the
  // first reading that finds the queue empty, so read it as the player does.
  for (int i = 0; i < 25; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(16));
    out->now();
  }
  const double now = out->now(), wall = wall_since(start);
  EXPECT_GT(now, 0.3);                                      // did not stop at 0.1 s
  EXPECT_LT(now, wall + 0.03) << "after " << wall << " s";  // and did not run ahead of the wall clock
}

TEST(AudioOutput, NoDeviceIsReportedNotThrown) {
  ScopedEnv driver("SDL_AUDIODRIVER", "no-such-driver");
  std::string why;
  auto out = AudioOutput::open(48000, why);
  EXPECT_FALSE(out);
  EXPECT_FALSE(why.empty());
}

TEST(SystemClock, AdvancesPausesAndRestarts) {
  const auto start = std::chrono::steady_clock::now();
  SystemClock clock;
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const double now = clock.now();
  EXPECT_GE(now, 0.05);
  EXPECT_LE(now, wall_since(start));
  clock.set_paused(true);
  const double t = clock.now();
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_EQ(clock.now(), t);
  clock.restart_at(10.0);
  EXPECT_EQ(clock.now(), 10.0);
  clock.set_paused(false);
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_GT(clock.now(), 10.0);
}

}  // namespace
}  // namespace nelf
