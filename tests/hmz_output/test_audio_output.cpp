// The volume applied to the samples (mpv's cubic scale, mute) and a multichannel device: on SDL's
// `disk` driver, which writes what the device would play to a file, a 5.1 chunk arrives as six
// interleaved channels in SDL's order, scaled by the volume.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <thread>
#include <vector>

#include "hmz_output/audio_output.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

TEST(ApplyVolume, HundredLeavesTheSamplesAndLowerIsCubic) {
  std::vector<float> samples = {0.5f, -0.25f, 1.0f};
  apply_volume(samples, 100.0, false);
  EXPECT_EQ(samples, (std::vector<float>{0.5f, -0.25f, 1.0f}));
  apply_volume(samples, 50.0, false);  // (50/100)^3 = 1/8
  EXPECT_FLOAT_EQ(samples[0], 0.0625f);
  EXPECT_FLOAT_EQ(samples[1], -0.03125f);
  EXPECT_FLOAT_EQ(samples[2], 0.125f);
}

TEST(ApplyVolume, MuteSilencesAndTheRangeIsZeroTo130) {
  std::vector<float> samples = {0.5f, -0.5f};
  apply_volume(samples, 100.0, true);
  EXPECT_EQ(samples, (std::vector<float>{0.f, 0.f}));
  samples = {0.5f};
  apply_volume(samples, 500.0, false);  // as 130
  EXPECT_NEAR(samples[0], 0.5 * 1.3 * 1.3 * 1.3, 1e-6);
  samples = {0.5f};
  apply_volume(samples, -3.0, false);  // as 0
  EXPECT_EQ(samples[0], 0.f);
}

TEST(AudioOutput, PlaysSixChannelsInOrderAtTheVolumeSet) {
  test::TempDir dir;
  const auto file = dir / "out.raw";
  test::ScopedEnv driver("SDL_AUDIODRIVER", "disk");
  test::ScopedEnv path("SDL_DISKAUDIOFILE", file.string());
  std::string why;
  {
    auto out = AudioOutput::open(48000, 6, why);
    ASSERT_TRUE(out) << why;
    ASSERT_EQ(out->channels(), 6);
    EXPECT_NE(out->description().find("6 channels"), std::string::npos) << out->description();
    // A stereo chunk does not fit a 5.1 device.
    EXPECT_THROW(out->queue(AudioChunk{0.0, std::vector<float>(200, 0.f), 2}), std::logic_error);
    // 0.2 s with 0.8 in the centre channel (SDL's third) and 0.4 in the LFE (its fourth).
    AudioChunk chunk{0.0, std::vector<float>(9600 * 6, 0.f), 6};
    for (std::size_t i = 0; i < 9600; ++i) {
      chunk.samples[i * 6 + 2] = 0.8f;
      chunk.samples[i * 6 + 3] = 0.4f;
    }
    out->set_volume(50.0, false);
    out->queue(chunk);
    out->set_paused(false);
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (out->buffered_s() > 0 && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_EQ(out->buffered_s(), 0.0) << "the disk driver did not take the samples";
  }
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<float> played(bytes.size() / sizeof(float));
  std::memcpy(played.data(), bytes.data(), played.size() * sizeof(float));
  ASSERT_GE(played.size(), 9600u * 6);
  double peak[6] = {};
  for (std::size_t i = 0; i + 6 <= played.size(); i += 6)
    for (int c = 0; c < 6; ++c) peak[c] = std::max(peak[c], static_cast<double>(std::abs(played[i + c])));
  EXPECT_NEAR(peak[2], 0.1, 1e-6);   // 0.8 at volume 50: x 1/8
  EXPECT_NEAR(peak[3], 0.05, 1e-6);  // 0.4 x 1/8
  for (int c : {0, 1, 4, 5}) EXPECT_EQ(peak[c], 0.0) << "channel " << c;
}

}  // namespace
}  // namespace nelf
