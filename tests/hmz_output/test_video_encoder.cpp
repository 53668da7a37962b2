#include <gtest/gtest.h>

#include <cstdlib>

#include "hmz_output/video_encoder.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::run_command;
using test::q;
using test::TempDir;

// A frame whose top half is red and bottom half is blue, with a black band in the middle rows.
PackedFrame test_frame(int width, int height, double pts, int black_from, int black_to) {
  PackedFrame f{width, height, 8, std::vector<std::uint8_t>(static_cast<std::size_t>(width * height * 4)), pts};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      std::uint8_t* p = &f.rgba[static_cast<std::size_t>((y * width + x) * 4)];
      const bool black = y >= black_from && y < black_to;
      const bool top = y < height / 2;
      p[0] = black ? 0 : top ? 220 : 20;
      p[1] = black ? 0 : 30;
      p[2] = black ? 0 : top ? 20 : 220;
      p[3] = 255;
    }
  return f;
}

std::string probe(const std::filesystem::path& file, const std::string& entries) {
  return run_command("ffprobe -v error -select_streams v:0 -count_frames -show_entries stream=" + entries +
                     " -of default=nw=1:nk=1 " + q(file))
      .out;
}

TEST(VideoEncoder, WritesH264WithFramesAndTimestamps) {
  TempDir dir;
  const auto out = dir / "out.mkv";
  {
    VideoEncoder enc(out, 64, 98, 24, 1, EncoderSettings{});
    for (int i = 0; i < 12; ++i) enc.write_video(test_frame(64, 98, i / 24.0, 48, 50));
    EXPECT_EQ(enc.codec_name(), "libx264");
    EXPECT_EQ(enc.pixel_format_name(), "yuv420p");
    enc.finish();
  }
  ASSERT_TRUE(std::filesystem::exists(out));
  EXPECT_EQ(probe(out, "width,height,nb_read_frames,pix_fmt,color_space"), "64\n98\nyuv420p\nbt709\n12\n");
  // Only the final file is left: no temporary beside it.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(VideoEncoder, OddHeightUses444) {
  TempDir dir;
  const auto out = dir / "odd.mkv";
  VideoEncoder enc(out, 64, 49, 30, 1, EncoderSettings{});
  EXPECT_EQ(enc.pixel_format_name(), "yuv444p");  // libx264 refuses 4:2:0 with an odd height
  for (int i = 0; i < 3; ++i) enc.write_video(test_frame(64, 49, i / 30.0, 20, 25));
  enc.finish();
  EXPECT_EQ(probe(out, "height,pix_fmt"), "49\nyuv444p\n");
}

// Every lossless encoder keeps the RGB planes, in Matroska too where it holds them only under a
// Windows tag (utvideo, ffvhuff, png): what ffmpeg itself writes and mpv plays.
TEST(VideoEncoder, LosslessCodecsKeepRgbExactly) {
  for (const std::string codec : {"ffv1", "utvideo", "ffvhuff", "png"}) {
    SCOPED_TRACE(codec);
    TempDir dir;
    const auto out = dir / "lossless.mkv";
    EncoderSettings settings;
    settings.codec = codec;
    VideoEncoder enc(out, 32, 20, 25, 1, settings);
    EXPECT_TRUE(enc.pixel_format_name() == "bgr0" || enc.pixel_format_name() == "gbrp" ||
                enc.pixel_format_name() == "rgb24")
        << enc.pixel_format_name();
    const PackedFrame frame = test_frame(32, 20, 0.0, 8, 12);
    enc.write_video(frame);
    enc.finish();
    const auto raw = dir / "raw.rgba";
    ASSERT_EQ(run_command("ffmpeg -v error -i " + q(out) + " -f rawvideo -pix_fmt rgba " + q(raw)).status, 0);
    const std::string bytes = test::read_file(raw);
    ASSERT_EQ(bytes.size(), frame.rgba.size());
    EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), frame.rgba.begin(),
                           [](char a, std::uint8_t b) { return static_cast<std::uint8_t>(a) == b; }));
  }
}

TEST(VideoEncoder, UnfinishedLeavesNothing) {
  TempDir dir;
  const auto out = dir / "cut.mp4";
  {
    VideoEncoder enc(out, 64, 64, 25, 1, EncoderSettings{});
    enc.write_video(test_frame(64, 64, 0, 0, 0));
  }  // destroyed without finish(): as after an error or Ctrl-C
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 0);
}

TEST(VideoEncoder, RefusesToOverwriteWithoutFlag) {
  TempDir dir;
  const auto out = dir / "exists.mkv";
  test::write_file(out, "keep me");
  try {
    VideoEncoder enc(out, 64, 64, 25, 1, EncoderSettings{});
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("pass -y to overwrite"), std::string::npos) << e.what();
  }
  EXPECT_EQ(test::read_file(out), "keep me");
}

TEST(VideoEncoder, BadSettingsAreClear) {
  TempDir dir;
  EncoderSettings bad_codec;
  bad_codec.codec = "nosuchcodec";
  EXPECT_THROW(VideoEncoder(dir / "a.mkv", 64, 64, 25, 1, bad_codec), std::invalid_argument);
  EXPECT_THROW(VideoEncoder(dir / "a.unknownext", 64, 64, 25, 1, EncoderSettings{}), std::invalid_argument);
  // What the container cannot hold says where it can go, or that no .mkv can either.
  const auto refusal = [&](const std::string& codec, const std::string& name) -> std::string {
    EncoderSettings settings;
    settings.codec = codec;
    try {
      VideoEncoder(dir / name, 64, 64, 25, 1, settings);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_NE(refusal("ffv1", "a.mp4").find("the mp4 container cannot hold ffv1 video (use .mkv)"), std::string::npos);
  EXPECT_NE(refusal("utvideo", "a.webm").find("cannot hold utvideo video (use .mkv)"), std::string::npos);
  EXPECT_NE(refusal("qtrle", "a.mkv").find("cannot hold qtrle video (choose another --codec)"), std::string::npos);
  EXPECT_THROW(VideoEncoder(dir / "missing-dir" / "a.mkv", 64, 64, 25, 1, EncoderSettings{}), std::runtime_error);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 0);
}

}  // namespace
}  // namespace nelf

namespace nelf {
namespace {

TEST(VideoEncoder, DeepSourcesKeepTenBits) {
  test::TempDir dir;
  EncoderSettings settings;
  settings.bits = 16;
  VideoEncoder enc(dir / "deep.mkv", 64, 64, 25, 1, settings);
  EXPECT_EQ(enc.pixel_format_name(), "yuv420p10le");
  PackedFrame frame{64, 64, 16, std::vector<std::uint8_t>(64 * 64 * 8, 0x80), 0.0};
  enc.write_video(frame);
  enc.finish();
}

}  // namespace
}  // namespace nelf

extern "C" {
#include <libavformat/avformat.h>
}

namespace nelf {
namespace {

struct InputCloser {
  void operator()(AVFormatContext* f) const { avformat_close_input(&f); }
};

// Audio (with its language tag), subtitles and chapters of the source are carried into the output.
TEST(VideoEncoder, CarriesAudioSubtitlesAndChapters) {
  test::TempDir dir;
  const auto source_path = dir / "source.mkv";
  test::write_file(dir / "subs.srt", "1\n00:00:00,000 --> 00:00:00,500\nhello\n");
  test::write_file(dir / "chapters.txt", ";FFMETADATA1\n[CHAPTER]\nTIMEBASE=1/1000\nSTART=0\nEND=500\ntitle=One\n");
  ASSERT_EQ(test::run_command("cd " + test::q(dir.path()) +
                              " && ffmpeg -v error -f lavfi -i testsrc2=size=64x36:rate=10 -f lavfi -i "
                              "sine=frequency=440:sample_rate=48000 -i subs.srt -i chapters.txt -map 0:v -map 1:a "
                              "-map 2:s -map_chapters 3 -t 1 -c:v libx264 -c:a flac -c:s srt "
                              "-metadata:s:a:0 language=fra source.mkv")
                .status,
            0);
  AVFormatContext* raw = nullptr;
  ASSERT_EQ(avformat_open_input(&raw, source_path.c_str(), nullptr, nullptr), 0);
  std::unique_ptr<AVFormatContext, InputCloser> source(raw);
  ASSERT_GE(avformat_find_stream_info(source.get(), nullptr), 0);

  const auto out = dir / "out.mkv";
  const CarriedStreamLayout carried = describe_carried_streams(*source);
  VideoEncoder enc(out, 64, 36, 10, 1, EncoderSettings{}, &carried);
  EXPECT_EQ(enc.carried_streams(), (std::vector<int>{1, 2}));
  AVPacket* packet = av_packet_alloc();
  int frame_index = 0;
  while (av_read_frame(source.get(), packet) >= 0) {
    if (packet->stream_index == 0)
      enc.write_video(test_frame(64, 36, frame_index++ / 10.0, 0, 0));
    else
      enc.write_source_packet(packet, packet->stream_index);
    av_packet_unref(packet);
  }
  av_packet_free(&packet);
  enc.finish();

  const auto streams = test::run_command(
      "ffprobe -v error -show_entries stream=codec_type,codec_name:stream_tags=language "
      "-show_chapters -of csv=p=0 " +
      test::q(out));
  EXPECT_NE(streams.out.find("h264,video"), std::string::npos) << streams.out;
  EXPECT_NE(streams.out.find("flac,audio,fra"), std::string::npos) << streams.out;
  EXPECT_NE(streams.out.find("subrip,subtitle"), std::string::npos) << streams.out;
  EXPECT_NE(streams.out.find("One"), std::string::npos) << streams.out;
  // Audio duration: end of the last audio packet.
  const auto packets = test::run_command(
      "ffprobe -v error -select_streams a:0 -show_entries packet=pts_time,duration_time "
      "-of csv=p=0 " +
      test::q(out));
  const auto last_line = packets.out.substr(packets.out.rfind('\n', packets.out.size() - 2) + 1);
  const double audio_end = std::atof(last_line.c_str()) + std::atof(last_line.substr(last_line.find(',') + 1).c_str());
  EXPECT_NEAR(audio_end, 1.0, 0.1) << packets.out;
}

}  // namespace
}  // namespace nelf

namespace nelf {
namespace {

TEST(VideoEncoder, GeneratedAudioTrackIsAac) {
  test::TempDir dir;
  const auto out = dir / "tone.mp4";
  VideoEncoder enc(out, 64, 64, 25, 1, EncoderSettings{});
  enc.add_audio_track(48000, 1);
  std::vector<float> second(48000);
  for (std::size_t i = 0; i < second.size(); ++i) second[i] = 0.3f * static_cast<float>(std::sin(i * 0.0576));
  for (int i = 0; i < 25; ++i) {
    enc.write_video(test_frame(64, 64, i / 25.0, 0, 0));
    enc.write_audio(second.data() + i * 1920, 1920);
  }
  enc.finish();
  const auto r = test::run_command(
      "ffprobe -v error -show_entries stream=codec_name,sample_rate,channels -of csv=p=0 " + test::q(out));
  EXPECT_NE(r.out.find("aac,48000,1"), std::string::npos) << r.out;
}

// PCM cannot go into MP4 as it is: it is re-encoded as AAC rather than lost.
TEST(VideoEncoder, ReencodesAudioTheContainerCannotHold) {
  test::TempDir dir;
  const auto source_path = dir / "pcm.mkv";
  ASSERT_EQ(test::run_command("ffmpeg -v error -f lavfi -i testsrc2=size=64x36:rate=10 -f lavfi -i "
                              "sine=frequency=440:sample_rate=44100 -t 1 -c:v libx264 -c:a pcm_s16le " +
                              test::q(source_path))
                .status,
            0);
  AVFormatContext* raw = nullptr;
  ASSERT_EQ(avformat_open_input(&raw, source_path.c_str(), nullptr, nullptr), 0);
  std::unique_ptr<AVFormatContext, InputCloser> source(raw);
  ASSERT_GE(avformat_find_stream_info(source.get(), nullptr), 0);
  const auto out = dir / "out.mp4";
  const CarriedStreamLayout carried = describe_carried_streams(*source);
  VideoEncoder enc(out, 64, 36, 10, 1, EncoderSettings{}, &carried);
  AVPacket* packet = av_packet_alloc();
  int frame_index = 0;
  while (av_read_frame(source.get(), packet) >= 0) {
    if (packet->stream_index == 0)
      enc.write_video(test_frame(64, 36, frame_index++ / 10.0, 0, 0));
    else
      enc.write_source_packet(packet, packet->stream_index);
    av_packet_unref(packet);
  }
  av_packet_free(&packet);
  enc.finish();
  const auto r =
      test::run_command("ffprobe -v error -show_entries stream=codec_name,sample_rate -of csv=p=0 " + test::q(out));
  EXPECT_NE(r.out.find("aac,44100"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace nelf
