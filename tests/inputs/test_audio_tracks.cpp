// A file's audio tracks: listed in the file's order with their language, codec and channels; the
// track asked for is the one decoded; a 5.1 track decoded for a 6-channel device keeps its
// channels where SDL plays them (the centre channel's tone stays in the third channel).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "inputs/audio_source.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

TEST(AudioTracks, ListsEachTrackWithItsLanguageCodecAndChannels) {
  test::TempDir dir;
  const auto clip = test::make_two_track_clip(dir / "two.mkv");
  const std::vector<AudioTrack> tracks = file_audio_tracks(clip.string(), false);
  ASSERT_EQ(tracks.size(), 2u);
  EXPECT_EQ(tracks[0].number, 1);
  EXPECT_EQ(tracks[0].language, "eng");
  EXPECT_EQ(tracks[0].codec, "aac");
  EXPECT_EQ(tracks[0].channels, 2);
  EXPECT_TRUE(tracks[0].is_default);
  EXPECT_EQ(tracks[1].number, 2);
  EXPECT_EQ(tracks[1].language, "ger");
  EXPECT_EQ(tracks[1].codec, "ac3");
  EXPECT_EQ(tracks[1].channels, 6);
  EXPECT_FALSE(tracks[1].is_default);
  EXPECT_TRUE(file_audio_tracks((dir / "none.mkv").string(), false).empty());
}

// Peak of each channel over the whole track.
std::vector<double> channel_peaks(AudioSource& source) {
  std::vector<double> peak(static_cast<std::size_t>(source.channels()), 0.0);
  while (auto chunk = source.next())
    for (std::size_t i = 0; i < chunk->samples.size(); ++i)
      peak[i % peak.size()] = std::max(peak[i % peak.size()], static_cast<double>(std::abs(chunk->samples[i])));
  return peak;
}

TEST(AudioTracks, TheSurroundTrackDecodesToSixChannelsInSdlOrder) {
  test::TempDir dir;
  const auto clip = test::make_two_track_clip(dir / "two.mkv");
  AudioSourceOptions options;
  options.channels = 6;
  options.track = 2;
  AudioSource source(clip.string(), options);
  EXPECT_EQ(source.codec_name(), "ac3");
  EXPECT_EQ(source.channels(), 6);
  const std::vector<double> peak = channel_peaks(source);
  EXPECT_GT(peak[2], 0.05);  // FC: SDL's third channel
  for (int c : {0, 1, 3, 4, 5}) EXPECT_LT(peak[static_cast<std::size_t>(c)], 0.01) << "channel " << c;
}

TEST(AudioTracks, TheDefaultIsTheFirstTrackAndAMissingOneIsAnError) {
  test::TempDir dir;
  const auto clip = test::make_two_track_clip(dir / "two.mkv");
  AudioSource first(clip.string());
  EXPECT_EQ(first.codec_name(), "aac");
  AudioSourceOptions options;
  options.track = 3;
  try {
    AudioSource third(clip.string(), options);
    FAIL() << "track 3 opened";
  } catch (const AudioError& e) {
    EXPECT_NE(std::string(e.what()).find("no audio track 3 (the file has 2)"), std::string::npos) << e.what();
  }
}

TEST(SdlChannelLayout, IsSdlsOrderForEachCount) {
  const auto order = [](int channels) {
    AVChannelLayout layout = sdl_channel_layout(channels);
    std::vector<AVChannel> names;
    for (int i = 0; i < layout.nb_channels; ++i) names.push_back(av_channel_layout_channel_from_index(&layout, i));
    av_channel_layout_uninit(&layout);
    return names;
  };
  EXPECT_EQ(order(2), (std::vector<AVChannel>{AV_CHAN_FRONT_LEFT, AV_CHAN_FRONT_RIGHT}));
  EXPECT_EQ(order(4),
            (std::vector<AVChannel>{AV_CHAN_FRONT_LEFT, AV_CHAN_FRONT_RIGHT, AV_CHAN_BACK_LEFT, AV_CHAN_BACK_RIGHT}));
  EXPECT_EQ(order(6), (std::vector<AVChannel>{AV_CHAN_FRONT_LEFT, AV_CHAN_FRONT_RIGHT, AV_CHAN_FRONT_CENTER,
                                              AV_CHAN_LOW_FREQUENCY, AV_CHAN_SIDE_LEFT, AV_CHAN_SIDE_RIGHT}));
  EXPECT_EQ(order(8), (std::vector<AVChannel>{AV_CHAN_FRONT_LEFT, AV_CHAN_FRONT_RIGHT, AV_CHAN_FRONT_CENTER,
                                              AV_CHAN_LOW_FREQUENCY, AV_CHAN_BACK_LEFT, AV_CHAN_BACK_RIGHT,
                                              AV_CHAN_SIDE_LEFT, AV_CHAN_SIDE_RIGHT}));
}

}  // namespace
}  // namespace nelf
