// Fuzz target: stereo metadata (inputs/stereo_metadata.*) as FFmpeg hands it to nelf. The first byte
// picks what the rest is:
//   0: raw side data bytes, attached to a stream (as Matroska StereoMode / MP4 st3d arrive) and to a
//      frame (as the H.264 frame-packing SEI arrives): any size, any type and flags;
//   1-4: a Matroska file, an MP4 file, an H.264 or an HEVC elementary stream, demuxed from memory
//      (a custom AVIOContext) and its first frames decoded, each stream's and frame's metadata read.
// Whatever is read is then mapped to a layout (layout_from_stereo_metadata) at the frame's aspect.
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/mem.h>
}

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <span>

#include "core/ffmpeg_raii.hpp"
#include "inputs/stereo_metadata.hpp"

namespace {

using namespace nelf::ffmpeg;

void map(const std::optional<nelf::StereoMetadata>& metadata, double aspect) {
  if (!metadata) return;
  try {
    (void)nelf::layout_from_stereo_metadata(*metadata, aspect);
  } catch (const nelf::UnsupportedStereoMetadata&) {
  }
}

void raw_side_data(std::span<const std::uint8_t> bytes) {
  const double aspect = bytes.empty() ? 0.0 : bytes[0] / 16.0;
  // Stream side data: owned by the stream once added.
  FormatContextPtr format(avformat_alloc_context());
  AVStream* stream = format ? avformat_new_stream(format.get(), nullptr) : nullptr;
  if (stream == nullptr) return;
  auto* copy = static_cast<std::uint8_t*>(av_malloc(std::max<std::size_t>(bytes.size(), 1)));
  if (copy == nullptr) return;
  if (!bytes.empty()) std::memcpy(copy, bytes.data(), bytes.size());
  if (av_stream_add_side_data(stream, AV_PKT_DATA_STEREO3D, copy, bytes.size()) < 0) {
    av_free(copy);
    return;
  }
  map(nelf::stereo_metadata_from_stream(*stream), aspect);

  FramePtr frame(av_frame_alloc());
  if (!frame) return;
  AVFrameSideData* side = av_frame_new_side_data(frame.get(), AV_FRAME_DATA_STEREO3D, bytes.size());
  if (side == nullptr) return;
  if (!bytes.empty()) std::memcpy(side->data, bytes.data(), bytes.size());
  map(nelf::stereo_metadata_from_frame(*frame), aspect);
}

struct MemoryInput {
  std::span<const std::uint8_t> bytes;
  std::size_t position = 0;
};

int read_memory(void* opaque, std::uint8_t* buffer, int size) {
  auto& in = *static_cast<MemoryInput*>(opaque);
  const std::size_t n = std::min(static_cast<std::size_t>(size), in.bytes.size() - in.position);
  if (n == 0) return AVERROR_EOF;
  std::memcpy(buffer, in.bytes.data() + in.position, n);
  in.position += n;
  return static_cast<int>(n);
}

std::int64_t seek_memory(void* opaque, std::int64_t offset, int whence) {
  auto& in = *static_cast<MemoryInput*>(opaque);
  const auto size = static_cast<std::int64_t>(in.bytes.size());
  if (whence == AVSEEK_SIZE) return size;
  std::int64_t target = offset;
  if ((whence & ~AVSEEK_FORCE) == SEEK_CUR)
    target += static_cast<std::int64_t>(in.position);
  else if ((whence & ~AVSEEK_FORCE) == SEEK_END)
    target += size;
  if (target < 0 || target > size) return AVERROR(EINVAL);
  in.position = static_cast<std::size_t>(target);
  return target;
}

struct IoContextDeleter {
  void operator()(AVIOContext* io) const {
    av_freep(&io->buffer);
    avio_context_free(&io);
  }
};

void demux(const char* format_name, std::span<const std::uint8_t> bytes) {
  MemoryInput input{bytes};
  constexpr int kBufferSize = 4096;
  auto* buffer = static_cast<unsigned char*>(av_malloc(kBufferSize));
  if (buffer == nullptr) return;
  std::unique_ptr<AVIOContext, IoContextDeleter> io(
      avio_alloc_context(buffer, kBufferSize, 0, &input, read_memory, nullptr, seek_memory));
  if (!io) {
    av_free(buffer);
    return;
  }
  AVFormatContext* raw = avformat_alloc_context();
  if (raw == nullptr) return;
  raw->pb = io.get();
  raw->flags |= AVFMT_FLAG_CUSTOM_IO;
  if (avformat_open_input(&raw, nullptr, av_find_input_format(format_name), nullptr) < 0) return;  // frees raw
  FormatContextPtr format(raw);
  if (avformat_find_stream_info(format.get(), nullptr) < 0) return;

  int video = -1;
  for (unsigned i = 0; i < format->nb_streams; ++i) {
    const AVStream& stream = *format->streams[i];
    const AVRational sar = stream.codecpar->sample_aspect_ratio;
    const double aspect =
        stream.codecpar->height > 0
            ? stream.codecpar->width * (sar.num > 0 && sar.den > 0 ? av_q2d(sar) : 1.0) / stream.codecpar->height
            : 0.0;
    map(nelf::stereo_metadata_from_stream(stream), aspect);
    if (video < 0 && stream.codecpar->codec_type == AVMEDIA_TYPE_VIDEO) video = static_cast<int>(i);
  }
  if (video < 0) return;

  const AVCodec* decoder = avcodec_find_decoder(format->streams[video]->codecpar->codec_id);
  if (decoder == nullptr) return;
  CodecContextPtr codec(avcodec_alloc_context3(decoder));
  if (!codec || avcodec_parameters_to_context(codec.get(), format->streams[video]->codecpar) < 0) return;
  codec->thread_count = 1;  // deterministic, and the other targets share the cores
  // The SEI is what this target is after, not large frames: those are the video target's.
  codec->max_pixels = 1920 * 1088;
  if (avcodec_open2(codec.get(), decoder, nullptr) < 0) return;

  PacketPtr packet(av_packet_alloc());
  FramePtr frame(av_frame_alloc());
  if (!packet || !frame) return;
  constexpr int kMaxPackets = 16;
  for (int n = 0; n < kMaxPackets && av_read_frame(format.get(), packet.get()) >= 0; ++n) {
    const bool ours = packet->stream_index == video;
    if (ours) avcodec_send_packet(codec.get(), packet.get());
    av_packet_unref(packet.get());
    if (!ours) continue;
    while (avcodec_receive_frame(codec.get(), frame.get()) >= 0) {
      const double aspect = frame->height > 0 ? static_cast<double>(frame->width) / frame->height : 0.0;
      map(nelf::stereo_metadata_from_frame(*frame), aspect);
      av_frame_unref(frame.get());
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  av_log_set_level(AV_LOG_QUIET);  // FFmpeg's complaints about broken input are the expected case
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::span<const std::uint8_t> rest(data + 1, size - 1);
  static constexpr const char* kFormats[] = {"matroska", "mov", "h264", "hevc"};
  const unsigned mode = data[0] % 5u;
  if (mode == 0)
    raw_side_data(rest);
  else
    demux(kFormats[mode - 1], rest);
  return 0;
}
