// The network rule (DESIGN.md §11) as the video and audio sources apply it: a local playlist that
// names segments on a server is refused before any connection, and the refusal names
// --allow-network; local inputs open as before. And the bound on opening a local file: a live
// playlist that waits for entries is given up, a pipe's writer is waited for.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include "inputs/audio_source.hpp"
#include "inputs/ffmpeg_input.hpp"
#include "inputs/video_source.hpp"
#include "support/media.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

// Port 9 is "discard": nothing listens there, so a connection attempt would fail with another error.
std::filesystem::path network_playlist(const test::TempDir& dir) {
  const auto path = dir / "list.m3u8";
  test::write_file(path,
                   "#EXTM3U\n#EXT-X-VERSION:3\n#EXT-X-TARGETDURATION:2\n#EXT-X-MEDIA-SEQUENCE:0\n"
                   "#EXTINF:2.0,\nhttp://127.0.0.1:9/seg0.ts\n#EXT-X-ENDLIST\n");
  return path;
}

template <typename Error, typename Open>
std::string error_of(Open open) {
  try {
    open();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(FfmpegInput, PlaylistWithNetworkSegmentsNamesAllowNetwork) {
  quiet_ffmpeg_logs(true);  // the HLS demuxer's own account of the refusal
  test::TempDir dir;
  const std::string list = network_playlist(dir).string();
  const std::string expected = list + ": opening it needs network access (http); pass --allow-network";
  EXPECT_EQ(error_of<VideoError>([&] { VideoSource source(list); }), expected);
  EXPECT_EQ(error_of<AudioError>([&] { AudioSource source(list); }), expected);
}

TEST(FfmpegInput, NetworkUrlNamesAllowNetwork) {
  EXPECT_EQ(error_of<AudioError>([] { AudioSource source("http://127.0.0.1:9/a.mp3"); }),
            "http://127.0.0.1:9/a.mp3: opening it needs network access (http); pass --allow-network");
}

TEST(FfmpegInput, LocalFilesAndPipesAreNoUrls) {
  EXPECT_TRUE(ffmpeg::is_url("http://example.org/a.mkv"));
  EXPECT_TRUE(ffmpeg::is_url("pipe:0"));
  EXPECT_FALSE(ffmpeg::is_url("film:3d.mkv"));
  EXPECT_FALSE(ffmpeg::is_url("/tmp/a.mkv"));
}

TEST(FfmpegInput, LocalInputsStillOpen) {
  test::TempDir dir;
  const auto clip = test::make_media(dir / "a:b.mkv",
                                     "-f lavfi -i testsrc2=s=64x36:r=10 -f lavfi -i sine=d=0.3 -frames:v 3 -c:v ffv1");
  ffmpeg::InputGuard guard;
  ffmpeg::FormatContextPtr format;
  ASSERT_GE(ffmpeg::open_input(format, clip.string(), guard), 0);
  EXPECT_TRUE(guard.refused_protocol.empty());
  EXPECT_NO_THROW(VideoSource source(clip.string()));
  EXPECT_NO_THROW(AudioSource source(clip.string()));
}

using Clock = std::chrono::steady_clock;

TEST(FfmpegInput, LocalLivePlaylistIsGivenUpAfterTheOpeningLimit) {
  quiet_ffmpeg_logs(true);
  test::TempDir dir;
  // Live (no #EXT-X-ENDLIST), and its one entry does not open: FFmpeg would reload it every 100 s.
  const auto list = dir / "live.m3u8";
  test::write_file(list, "#EXTM3U\n#EXT-X-TARGETDURATION:100\n#EXTINF:100,\nmissing.ts\n");
  ffmpeg::InputGuard guard;
  guard.opening_limit = std::chrono::milliseconds(500);
  ffmpeg::FormatContextPtr format;
  const auto start = Clock::now();
  int status = ffmpeg::open_input(format, list.string(), guard);
  if (status >= 0) status = ffmpeg::find_stream_info(format.get(), guard);
  EXPECT_LT(status, 0);
  EXPECT_LT(Clock::now() - start, std::chrono::seconds(10));
  ASSERT_TRUE(ffmpeg::guard_stop(list.string(), guard));
  EXPECT_EQ(*ffmpeg::guard_stop(list.string(), guard),
            list.string() +
                ": still not open after 0.5 s, given up (a live playlist whose entries do not open?); check what "
                "it lists");
}

TEST(FfmpegInput, ReadingAfterProbingIsNotBoundByTheOpeningLimit) {
  test::TempDir dir;
  const auto clip = test::make_media(dir / "a.mkv", "-f lavfi -i testsrc2=s=64x36:r=10 -frames:v 3 -c:v ffv1");
  ffmpeg::InputGuard guard;
  guard.opening_limit = std::chrono::milliseconds(200);
  ffmpeg::FormatContextPtr format;
  ASSERT_GE(ffmpeg::open_input(format, clip.string(), guard), 0);
  ASSERT_GE(ffmpeg::find_stream_info(format.get(), guard), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  ffmpeg::PacketPtr packet(av_packet_alloc());
  EXPECT_EQ(av_read_frame(format.get(), packet.get()), 0);
  EXPECT_FALSE(ffmpeg::guard_stop(clip.string(), guard));
}

TEST(FfmpegInput, APipesWriterIsWaitedForPastTheOpeningLimit) {
  test::TempDir dir;
  const auto clip = test::make_media(dir / "a.mkv", "-f lavfi -i testsrc2=s=64x36:r=10 -frames:v 3 -c:v ffv1");
  const auto fifo = dir / "fifo.mkv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // The writer starts well after the limit, as a slow encoder feeding nelf through a named pipe.
  std::thread writer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(800));
    std::ifstream in(clip, std::ios::binary);
    std::ofstream out(fifo, std::ios::binary);
    out << in.rdbuf();
  });
  ffmpeg::InputGuard guard;
  guard.opening_limit = std::chrono::milliseconds(200);
  ffmpeg::FormatContextPtr format;
  const int opened = ffmpeg::open_input(format, fifo.string(), guard);
  const int found = opened >= 0 ? ffmpeg::find_stream_info(format.get(), guard) : opened;
  writer.join();
  EXPECT_GE(opened, 0);
  EXPECT_GE(found, 0);
  EXPECT_FALSE(ffmpeg::guard_stop(fifo.string(), guard));
}

}  // namespace
}  // namespace nelf
