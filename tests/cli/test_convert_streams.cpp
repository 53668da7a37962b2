// `nelf convert` and the streams it carries from a release-style file (support/release_media.hpp):
// --start/--duration cut chapters and subtitle events to the range, the output lasts as long as its
// video, carried subtitles lose their default flag, and text subtitles become mov_text in MP4. Read
// back with ffprobe and mpv.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/media.hpp"
#include "support/release_media.hpp"
#include "support/test_support.hpp"

namespace nelf::test {
namespace {

nlohmann::json ffprobe_json(const std::filesystem::path& path, const std::string& what) {
  const CommandResult r = run_command("ffprobe -v error -of json " + what + " " + q(path));
  EXPECT_EQ(r.status, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

double number(const nlohmann::json& value) { return std::stod(value.get<std::string>()); }

struct Event {
  double start, length;
};

// The packets (events) of subtitle stream `stream` (s:0, s:1) of `path`.
std::vector<Event> subtitle_events(const std::filesystem::path& path, const std::string& stream) {
  std::vector<Event> events;
  const nlohmann::json packets =
      ffprobe_json(path, "-select_streams " + stream + " -show_entries packet=pts_time,duration_time");
  EXPECT_TRUE(packets.contains("packets")) << packets.dump();
  for (const auto& p : packets["packets"]) events.push_back({number(p["pts_time"]), number(p["duration_time"])});
  return events;
}

CommandResult convert(const TempDir& dir, const std::filesystem::path& in, const std::filesystem::path& out,
                      const std::string& extra) {
  return run_nelf("convert " + q(in) + " " + q(out) + " --signal sbs --quiet --profile " + q(write_small_profile(dir)) +
                  " " + extra);
}

// The file's streams start 0.023 s late (the muxer's shift for the AAC priming): times come back
// within this of the plain numbers.
constexpr double kSlack = 0.04;

TEST(ConvertStreams, StartAndDurationCutChaptersSubtitlesAndTheContainer) {
  TempDir dir;
  const auto in = make_release_mkv(dir.path());
  const auto out = dir / "cut.mkv";
  const CommandResult r = convert(dir, in, out, "--start 2 --duration 2");
  ASSERT_EQ(r.status, 0) << r.err;

  // A (0-1.5) lies before the range; B (1.5-3) runs at the start point and starts at 0; C is cut
  // at the end.
  const nlohmann::json chapters = ffprobe_json(out, "-show_chapters")["chapters"];
  ASSERT_EQ(chapters.size(), 2u) << chapters.dump();
  EXPECT_EQ(chapters[0]["tags"]["title"], "B");
  EXPECT_NEAR(number(chapters[0]["start_time"]), 0.0, 1e-6);
  EXPECT_NEAR(number(chapters[0]["end_time"]), 1.0, kSlack);
  EXPECT_EQ(chapters[1]["tags"]["title"], "C");
  EXPECT_NEAR(number(chapters[1]["end_time"]), 2.0, 1e-3);

  // "first" (1-3) is on screen at 2: from 0 for 1 s; "second" (3.5-5.5) cut at the end.
  const std::vector<Event> english = subtitle_events(out, "s:0");
  ASSERT_EQ(english.size(), 2u);
  EXPECT_NEAR(english[0].start, 0.0, 1e-6);
  EXPECT_NEAR(english[0].length, 1.0, kSlack);
  EXPECT_NEAR(english[1].start, 1.5, kSlack);
  EXPECT_NEAR(english[1].start + english[1].length, 2.0, 1e-3);
  const std::vector<Event> french = subtitle_events(out, "s:1");
  ASSERT_EQ(french.size(), 1u);
  EXPECT_NEAR(french[0].start, 0.0, 1e-6);
  EXPECT_NEAR(french[0].length, 0.5, kSlack);

  // The container lasts as long as the video: 20 frames at 10 fps (the audio, in 32 ms AC-3
  // frames, ends no later).
  EXPECT_NEAR(number(ffprobe_json(out, "-show_entries format=duration")["format"]["duration"]), 2.0, 1e-3);
}

TEST(ConvertStreams, CarriedSubtitlesLoseTheirDefaultFlagAndSaySo) {
  TempDir dir;
  const auto in = make_release_mkv(dir.path());
  const auto out = dir / "out.mkv";
  const CommandResult r = convert(dir, in, out, "--duration 1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nelf: 2 subtitle streams carried without the default flag"), std::string::npos) << r.err;
  const nlohmann::json streams = ffprobe_json(
      out, "-show_entries stream=codec_type,codec_name:stream_disposition=default:stream_tags=language,title");
  int subtitles = 0;
  for (const auto& s : streams["streams"]) {
    if (s["codec_type"] != "subtitle") continue;
    ++subtitles;
    EXPECT_EQ(s["disposition"]["default"], 0) << s.dump();
    EXPECT_EQ(s["codec_name"], "subrip");
  }
  EXPECT_EQ(subtitles, 2);
  EXPECT_EQ(streams["streams"][4]["tags"]["title"], "French");
  // mpv, left to itself, shows no subtitle track of it ("(+)" marks a selected track).
  const CommandResult mpv =
      run_command("timeout 60 mpv --no-config --vo=null --ao=null --frames=1 --msg-level=all=info " + q(out));
  ASSERT_EQ(mpv.status, 0) << mpv.err;
  EXPECT_NE(mpv.out.find("Subs"), std::string::npos) << mpv.out;
  EXPECT_EQ(mpv.out.find("(+) Subs"), std::string::npos) << mpv.out;
}

TEST(ConvertStreams, TextSubtitlesBecomeMovTextInMp4) {
  TempDir dir;
  const auto in = make_release_mkv(dir.path());
  const auto out = dir / "out.mp4";
  const CommandResult r = convert(dir, in, out, "--start 2 --duration 2");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("dropped"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(mp4 enables the first one"), std::string::npos)
      << r.err;  // says MP4 enables the first one anyway
  const nlohmann::json streams = ffprobe_json(out, "-show_entries stream=codec_type,codec_name:stream_tags=language");
  std::vector<std::string> languages;
  for (const auto& s : streams["streams"])
    if (s["codec_type"] == "subtitle") {
      EXPECT_EQ(s["codec_name"], "mov_text");
      languages.push_back(s["tags"]["language"]);
    }
  EXPECT_EQ(languages, (std::vector<std::string>{"eng", "fre"}));
  // The events' text and times, as ffmpeg reads them back out of the MP4.
  const CommandResult srt = run_command("ffmpeg -nostdin -v error -i " + q(out) + " -map 0:s:0 -f srt -");
  ASSERT_EQ(srt.status, 0) << srt.err;
  EXPECT_NE(srt.out.find("00:00:00,000 --> 00:00:0"), std::string::npos) << srt.out;
  EXPECT_NE(srt.out.find("first"), std::string::npos) << srt.out;
  EXPECT_NE(srt.out.find("second"), std::string::npos) << srt.out;
  EXPECT_NEAR(number(ffprobe_json(out, "-show_entries format=duration")["format"]["duration"]), 2.0, 1e-3);
}

TEST(ConvertStreams, ARangeAfterEveryChapterStartKeepsTheLastOne) {
  TempDir dir;
  const auto in = make_release_mkv(dir.path());
  const auto out = dir / "late.mkv";
  ASSERT_EQ(convert(dir, in, out, "--start 4").status, 0);
  const nlohmann::json chapters = ffprobe_json(out, "-show_chapters")["chapters"];
  ASSERT_EQ(chapters.size(), 1u) << chapters.dump();
  EXPECT_EQ(chapters[0]["tags"]["title"], "C");
  EXPECT_NEAR(number(chapters[0]["start_time"]), 0.0, 1e-6);
  EXPECT_NEAR(number(chapters[0]["end_time"]), 2.0, kSlack);
  // "second" (3.5-5.5) from 0 to 1.5; nothing of the French, which ended at 2.5.
  const std::vector<Event> english = subtitle_events(out, "s:0");
  ASSERT_EQ(english.size(), 1u);
  EXPECT_NEAR(english[0].start, 0.0, 1e-6);
  EXPECT_NEAR(english[0].length, 1.5, kSlack);
  EXPECT_TRUE(subtitle_events(out, "s:1").empty());
}

}  // namespace
}  // namespace nelf::test
