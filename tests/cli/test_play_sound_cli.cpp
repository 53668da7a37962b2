// `nelf play`'s sound options on a film with two audio tracks (stereo "eng", 5.1 "ger"): --aid and
// --alang choose the track and the status line names it; a 5.1 track opens the device (SDL's dummy
// driver takes six channels) with six; a track or language the file lacks, or a bad --aid or
// --volume, is one line and status 2 before anything plays; # switches tracks while playing.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "support/media.hpp"
#include "support/test_support.hpp"
#include "support/xvfb.hpp"

namespace nelf::test {
namespace {

class PlaySoundCli : public ::testing::Test {
 protected:
  TempDir dir_;
  std::filesystem::path clip_ = make_two_track_clip(dir_ / "two.mkv");
  CommandResult play(const std::string& options) const {
    return run_command("SDL_AUDIODRIVER=dummy LP_NUM_THREADS=2 timeout 60 " + std::string(NELF_BINARY) + " play " +
                       q(clip_) + " --layout sbs --output offscreen --profile " + q(write_small_profile(dir_)) + " " +
                       options);
  }
};

TEST_F(PlaySoundCli, TheDefaultTrackIsTheFirstInStereo) {
  const auto r = play("");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: sound: dummy, 48000 Hz, 2 channels, 512-sample buffer, audio track 1: eng, aac, 2 "
                       "channels (default)\n"),
            std::string::npos)
      << r.err;
}

TEST_F(PlaySoundCli, AidChoosesTheSurroundTrackAndItPlaysInSixChannels) {
  const auto r = play("--aid 2");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: sound: dummy, 48000 Hz, 6 channels, 512-sample buffer, audio track 2: ger, ac3, 6 "
                       "channels\n"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("mixed down"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("frames shown"), std::string::npos) << r.err;
}

TEST_F(PlaySoundCli, AlangTakesTheFirstLanguageATrackHas) {
  auto r = play("--alang GER");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("audio track 2: ger"), std::string::npos) << r.err;
  r = play("--alang fre,eng,ger");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("audio track 1: eng"), std::string::npos) << r.err;
}

TEST_F(PlaySoundCli, AidNoPlaysWithoutSoundAndSaysSo) {
  const auto r = play("--aid no");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: --aid no: playing without sound\n"), std::string::npos) << r.err;
}

// One line after the input's: the error, naming the tracks there are; nothing played.
void expect_track_error(const CommandResult& r, const std::string& line) {
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("nelf: " + line + "\n"), std::string::npos) << r.err;
  EXPECT_LE(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
  EXPECT_EQ(r.err.find("playing on"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("frames shown"), std::string::npos) << r.err;
}

TEST_F(PlaySoundCli, ATrackOrLanguageTheFileLacksIsOneLineListingItsTracks) {
  const std::string tracks = "the input has track 1: eng, aac, 2 channels (default); track 2: ger, ac3, 6 channels";
  expect_track_error(play("--aid 3"), "no audio track 3 (--aid): " + tracks);
  expect_track_error(play("--alang fre,ita"), "no audio track in fre,ita (--alang): " + tracks);
}

TEST_F(PlaySoundCli, BadAidAndVolumeValuesAreOneLine) {
  expect_track_error(play("--aid 0"), "--aid 0: a track number from 1, auto or no");
  expect_track_error(play("--aid two"), "--aid two: a track number from 1, auto or no");
  const auto r = play("--volume 131");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--volume"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// # while playing: the next track, said in the terminal as the status line said the first; the film
// plays on to its end.
TEST_F(PlaySoundCli, HashSwitchesToTheNextTrack) {
  XvfbServer xvfb;
  const auto long_clip = make_two_track_clip(dir_ / "long.mkv", 8);
  const auto r = run_command(
      "DISPLAY=" + xvfb.display_name() + " SDL_AUDIODRIVER=dummy LP_NUM_THREADS=2 " + std::string(NELF_BINARY) +
      " play " + q(long_clip) + " --layout sbs --profile " + q(write_small_profile(dir_)) +
      " & pid=$!; (sleep 60; kill -KILL $pid) 2>/dev/null & guard=$!; export DISPLAY=" + xvfb.display_name() +
      "; w=$(timeout 20 xdotool search --sync --name '^nelf: ' | head -1); sleep 1.5; "
      "xdotool key --window $w numbersign; sleep 1.5; xdotool key --window $w numbersign; sleep 1; "
      "xdotool key --window $w q; wait $pid; status=$?; kill $guard; echo status $status");
  EXPECT_NE(r.out.find("status 0\n"), std::string::npos) << r.out << r.err;
  const auto second = r.err.find("nelf: Audio: track 2/2 (ger, ac3, 5.1)\n");
  EXPECT_NE(second, std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nelf: Audio: track 1/2 (eng, aac, stereo)\n", second), std::string::npos) << r.err;
}

}  // namespace
}  // namespace nelf::test
