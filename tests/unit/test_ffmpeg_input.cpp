// The network rule (DESIGN.md §11) as the video and audio sources apply it: a local playlist that
// names segments on a server is refused before any connection, and the refusal names
// --allow-network; local inputs open as before.
#include <gtest/gtest.h>

#include <string>

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
  ffmpeg::NetworkGuard guard;
  ffmpeg::FormatContextPtr format;
  ASSERT_GE(ffmpeg::open_input(format, clip.string(), guard), 0);
  EXPECT_TRUE(guard.refused_protocol.empty());
  EXPECT_NO_THROW(VideoSource source(clip.string()));
  EXPECT_NO_THROW(AudioSource source(clip.string()));
}

}  // namespace
}  // namespace nelf
