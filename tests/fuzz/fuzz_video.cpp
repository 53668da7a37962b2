// Fuzz target: the FFmpeg demux + first-frame path (inputs/video_source.*): the input is written as
// a media file, opened by VideoSource with its defaults (the network guard on: FFmpeg may only use
// the file and pipe protocols, so a playlist in the input cannot reach out) and its first frames
// decoded and converted to RGBA. The first byte picks the file's extension (FFmpeg's probe weighs
// it); the rest is the file.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>

#include "inputs/video_source.hpp"
#include "temp_input.hpp"

namespace {

void require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "broken invariant: %s\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  nelf::quiet_ffmpeg_logs(true);  // as the CLI runs it: broken input is reported by nelf, not FFmpeg
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const nelf::fuzz::TempInput temp("nelf-fuzz-video");
  if (size == 0) return 0;
  static constexpr const char* kExtensions[] = {".mkv", ".mp4", ".ts", ".m2ts", ".mov", ".avi", ".h264", ".webm"};
  const std::string name = std::string("video") + kExtensions[data[0] % 8];
  const std::span<const std::uint8_t> file(data + 1, size - 1);
  try {
    nelf::VideoSource source(temp.write(name, file).string());
    const nelf::VideoInfo& info = source.info();
    require(info.width > 0 && info.height > 0, "an opened video has a frame size");
    for (int n = 0; n < 2; ++n) {
      const auto frame = source.next_frame();
      if (!frame) break;
      require(frame->width > 0 && frame->height > 0, "a decoded frame has a size");
      const std::size_t pixels = static_cast<std::size_t>(frame->width) * static_cast<std::size_t>(frame->height) * 4;
      require(frame->bits == 8 ? frame->rgba8.size() == pixels : frame->rgba16.size() == pixels,
              "a frame holds all its pixels");
    }
    (void)source.stereo_metadata();
  } catch (const nelf::VideoError&) {
  }
  return 0;
}
