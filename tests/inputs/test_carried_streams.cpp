// Carried streams of a media file (inputs/file_carried_streams.hpp): the layout an encoder sets its
// streams up from, and the packets it copies, exactly those of the file in file order, shifted to
// the video's origin and handed out in step with the video: a call up to a time stops only at a
// carried packet later than it (in MPEG-TS the audio lies behind the video in the file).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/carried_streams.hpp"
#include "inputs/file_carried_streams.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::make_media;
using test::q;
using test::TempDir;

// One packet as read: enough to tell two apart.
struct Packet {
  int stream = -1;
  std::int64_t pts = 0, dts = 0;
  double t = 0;  // pts in seconds on the file's clock
  std::vector<std::uint8_t> data;
  double length = 0;  // duration in seconds
  bool operator==(const Packet& o) const {
    return stream == o.stream && pts == o.pts && dts == o.dts && data == o.data;
  }
};

// Every packet of streams `wanted` in `path`, in file order, read with FFmpeg directly.
std::vector<Packet> read_directly(const std::filesystem::path& path, const std::vector<int>& wanted) {
  AVFormatContext* raw = nullptr;
  EXPECT_EQ(avformat_open_input(&raw, path.c_str(), nullptr, nullptr), 0);
  ffmpeg::FormatContextPtr format(raw);
  EXPECT_GE(avformat_find_stream_info(format.get(), nullptr), 0);
  std::vector<Packet> packets;
  ffmpeg::PacketPtr p(av_packet_alloc());
  while (av_read_frame(format.get(), p.get()) >= 0) {
    if (std::find(wanted.begin(), wanted.end(), p->stream_index) != wanted.end()) {
      const AVRational tb = format->streams[p->stream_index]->time_base;
      const std::int64_t ts = p->pts != AV_NOPTS_VALUE ? p->pts : p->dts;
      packets.push_back({p->stream_index,
                         p->pts,
                         p->dts,
                         ts * av_q2d(tb),
                         {p->data, p->data + p->size},
                         static_cast<double>(p->duration) * av_q2d(tb)});
    }
    av_packet_unref(p.get());
  }
  return packets;
}

Packet described(const AVPacket& p) { return {p.stream_index, p.pts, p.dts, 0, {p.data, p.data + p.size}, 0}; }

// Video, audio tagged French, SubRip subtitles (unless `codecs` has -sn), one chapter and a title:
// 1 s at 10 fps.
std::filesystem::path make_clip(const TempDir& dir, const std::string& name, const std::string& codecs) {
  const bool subtitles = codecs.find("-sn") == std::string::npos;
  test::write_file(dir / "subs.srt",
                   "1\n00:00:00,000 --> 00:00:00,500\nhello\n\n2\n00:00:00,600 --> 00:00:00,900\nbye\n");
  test::write_file(dir / "chapters.txt",
                   ";FFMETADATA1\ntitle=Clip\n[CHAPTER]\nTIMEBASE=1/1000\nSTART=0\nEND=500\ntitle=One\n");
  return make_media(dir / name,
                    "-f lavfi -i testsrc2=size=64x36:rate=10 -f lavfi -i sine=frequency=440:sample_rate=48000 -i " +
                        q(dir / "subs.srt") + " -i " + q(dir / "chapters.txt") + " -map 0:v -map 1:a " +
                        (subtitles ? "-map 2:s " : "") +
                        "-map_metadata 3 -map_chapters 3 -t 1 -c:v libx264 -preset ultrafast "
                        "-metadata:s:a:0 language=fra " +
                        codecs);
}

std::string tag(const AVDictionary* dictionary, const char* key) {
  const AVDictionaryEntry* e = av_dict_get(dictionary, key, nullptr, 0);
  return e ? e->value : "";
}

TEST(FileCarriedStreams, DescribeTheAudioSubtitlesChaptersAndTitle) {
  TempDir dir;
  const auto clip = make_clip(dir, "clip.mkv", "-c:a flac -c:s srt");
  const auto carried = open_file_carried_streams(clip.string(), 0.0, false);
  const CarriedStreamLayout& layout = carried->layout();
  ASSERT_EQ(layout.streams.size(), 2u);
  EXPECT_EQ(layout.streams[0].index, 1);
  EXPECT_EQ(layout.streams[0].codec->codec_id, AV_CODEC_ID_FLAC);
  EXPECT_EQ(layout.streams[0].codec->sample_rate, 48000);
  EXPECT_EQ(tag(layout.streams[0].metadata.get(), "language"), "fra");
  EXPECT_EQ(layout.streams[0].time_base.den, 1000);  // Matroska's
  EXPECT_EQ(layout.streams[1].index, 2);
  EXPECT_EQ(layout.streams[1].codec->codec_id, AV_CODEC_ID_SUBRIP);
  ASSERT_EQ(layout.chapters.size(), 1u);
  EXPECT_EQ(tag(layout.chapters[0].metadata.get(), "title"), "One");
  EXPECT_EQ(av_rescale_q(layout.chapters[0].end, layout.chapters[0].time_base, {1, 1000}), 500);
  EXPECT_EQ(tag(layout.metadata.get(), "title"), "Clip");
}

// Takes packets as convert does: up to each frame's end in turn, then the rest.
std::vector<std::vector<Packet>> take_in_steps(CarriedStreams& carried, const std::vector<int>& wanted,
                                               const std::vector<double>& untils) {
  std::vector<std::vector<Packet>> steps;
  for (double until : untils) {
    steps.emplace_back();
    while (auto p = carried.next_packet(wanted, until, std::nullopt)) steps.back().push_back(described(*p));
  }
  steps.emplace_back();
  while (auto p = carried.next_packet(wanted, std::nullopt, std::nullopt)) steps.back().push_back(described(*p));
  return steps;
}

// What each step must hold: the wanted packets in file order up to the first later than its time.
std::vector<std::vector<Packet>> expected_steps(const std::vector<Packet>& all, const std::vector<double>& untils) {
  std::vector<std::vector<Packet>> steps;
  std::size_t k = 0;
  for (double until : untils) {
    steps.emplace_back();
    while (k < all.size() && all[k].t <= until) steps.back().push_back(all[k++]);
  }
  steps.emplace_back(all.begin() + static_cast<std::ptrdiff_t>(k), all.end());
  return steps;
}

std::vector<double> frame_ends() {
  std::vector<double> untils;
  for (int i = 1; i <= 10; ++i) untils.push_back(i / 10.0 - 1e-6);
  return untils;
}

TEST(FileCarriedStreams, HandOutTheFilesPacketsInOrderUpToEachTime) {
  TempDir dir;
  const auto clip = make_clip(dir, "clip.mkv", "-c:a flac -c:s srt");
  const std::vector<int> wanted{1, 2};
  const auto all = read_directly(clip, wanted);
  ASSERT_GT(all.size(), 10u);
  auto carried = open_file_carried_streams(clip.string(), 0.0, false);
  EXPECT_EQ(take_in_steps(*carried, wanted, frame_ends()), expected_steps(all, frame_ends()));
  EXPECT_FALSE(carried->next_packet(wanted, std::nullopt, std::nullopt));
  // Nothing wanted: nothing read.
  auto again = open_file_carried_streams(clip.string(), 0.0, false);
  EXPECT_FALSE(again->next_packet({}, std::nullopt, std::nullopt));
  EXPECT_TRUE(again->next_packet(wanted, std::nullopt, std::nullopt));
}

TEST(FileCarriedStreams, InTransportStreamsOnlyACarriedPacketWaits) {
  TempDir dir;
  const auto clip = make_clip(dir, "clip.ts", "-c:a aac -sn");
  const std::vector<int> wanted{1};
  const auto all = read_directly(clip, wanted);
  ASSERT_GT(all.size(), 10u);
  // The case the rule is for: audio the file holds after video of a later time.
  const auto both = read_directly(clip, {0, 1});
  double latest_video = -1e9;
  bool audio_behind = false;
  for (const Packet& p : both) {
    if (p.stream == 0) latest_video = std::max(latest_video, p.t);
    if (p.stream == 1 && p.t < latest_video - 0.05) audio_behind = true;
  }
  ASSERT_TRUE(audio_behind) << "the test clip no longer shows what MPEG-TS does";
  auto carried = open_file_carried_streams(clip.string(), 0.0, false);
  ASSERT_EQ(carried->layout().streams.size(), 1u);
  // On the file's own clock (MPEG-TS starts at 1.4 s), from its first audio packet on.
  std::vector<double> untils;
  for (double u : frame_ends()) untils.push_back(u + all.front().t);
  EXPECT_EQ(take_in_steps(*carried, wanted, untils), expected_steps(all, untils));
}

TEST(FileCarriedStreams, ShiftToTheOriginAndStopAtTheEnd) {
  // (Subtitle events on screen at the origin, and cut at the end: tests/cli/test_convert_streams.)
  TempDir dir;
  const auto clip = make_clip(dir, "clip.mkv", "-c:a flac -c:s srt");
  const std::vector<int> wanted{1, 2};
  auto carried = open_file_carried_streams(clip.string(), 0.5, false);
  std::vector<Packet> got;
  while (auto p = carried->next_packet(wanted, std::nullopt, 0.3)) got.push_back(described(*p));
  std::vector<Packet> expected;
  for (Packet p : read_directly(clip, wanted)) {
    if (p.t - 0.5 < -1e-6 || p.t - 0.5 >= 0.3) continue;
    // Audio that would play past the end is left out (the output ends with its video).
    if (p.stream == 1 && p.t - 0.5 + p.length > 0.3 + 1e-3) continue;
    p.pts -= 500;  // 0.5 s in Matroska's milliseconds
    p.dts -= 500;
    expected.push_back(p);
  }
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(got, expected);
}

}  // namespace
}  // namespace nelf
