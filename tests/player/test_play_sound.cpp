// Choosing the audio track for `nelf play`: --aid's number, else --alang's first language a track
// has, else the file's default; a number or language the file lacks is one line listing the tracks.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/user_error.hpp"
#include "player/play_sound.hpp"

namespace nelf::playback {
namespace {

const std::vector<AudioTrack> tracks = {
    {1, "eng", "aac", 2, true}, {2, "GER", "ac3", 6, false}, {3, "eng", "ac3", 6, false}};

TEST(ChooseAudioTrack, NumberThenLanguagesThenTheDefault) {
  EXPECT_EQ(choose_audio_track(tracks, std::nullopt, {}), 0);
  EXPECT_EQ(choose_audio_track(tracks, 3, {"ger"}), 3);  // --aid wins
  EXPECT_EQ(choose_audio_track(tracks, std::nullopt, {"ger"}), 2);
  EXPECT_EQ(choose_audio_track(tracks, std::nullopt, {"fre", "ENG", "ger"}), 1);  // first language, first track
}

TEST(ChooseAudioTrack, AMissingTrackNamesTheTracksThereAre) {
  try {
    choose_audio_track(tracks, 4, {});
    FAIL();
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()),
              "no audio track 4 (--aid): the input has track 1: eng, aac, 2 channels (default); track 2: GER, ac3, 6 "
              "channels; track 3: eng, ac3, 6 channels");
    EXPECT_EQ(e.status(), 2);
  }
  try {
    choose_audio_track(tracks, std::nullopt, {"fre", "ita"});
    FAIL();
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("no audio track in fre,ita (--alang): the input has track 1"),
              std::string::npos)
        << e.what();
  }
  try {
    choose_audio_track({}, 1, {});
    FAIL();
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), "no audio track 1 (--aid): the input has no audio tracks to choose from");
  }
}

}  // namespace
}  // namespace nelf::playback
