#pragma once
// Owning handles for FFmpeg objects: every allocation is released by a unique_ptr deleter, so an
// exception thrown half-way through opening or decoding a file leaks nothing.
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/dict.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libswscale/swscale.h>
}

#include <cstring>
#include <memory>
#include <string>
#include <type_traits>

namespace nelf::ffmpeg {

// The value of an FFmpeg enum field as the integer it holds. FFmpeg copies tags from the bitstream
// unchecked (an H.264 VUI may say colour matrix 84), and a newer FFmpeg at run time may store a
// value these headers do not list: loading such a field as its enum type is undefined behaviour in
// C++ (fuzzing found both, docs/fuzzing.md findings 1 and 8); reading its bytes is not.
template <typename Enum>
std::underlying_type_t<Enum> raw_value(const Enum& field) {
  static_assert(std::is_enum_v<Enum>);
  std::underlying_type_t<Enum> value{};
  std::memcpy(&value, &field, sizeof value);
  return value;
}

struct FormatContextDeleter {
  // avformat_close_input also frees the context and closes the AVIOContext it opened.
  void operator()(AVFormatContext* context) const { avformat_close_input(&context); }
};
struct CodecContextDeleter {
  void operator()(AVCodecContext* context) const { avcodec_free_context(&context); }
};
struct FrameDeleter {
  void operator()(AVFrame* frame) const { av_frame_free(&frame); }
};
struct PacketDeleter {
  void operator()(AVPacket* packet) const { av_packet_free(&packet); }
};
struct SwsContextDeleter {
  void operator()(SwsContext* context) const { sws_freeContext(context); }
};
struct CodecParametersDeleter {
  void operator()(AVCodecParameters* parameters) const { avcodec_parameters_free(&parameters); }
};
struct DictionaryDeleter {
  void operator()(AVDictionary* dictionary) const { av_dict_free(&dictionary); }
};

using FormatContextPtr = std::unique_ptr<AVFormatContext, FormatContextDeleter>;
using CodecContextPtr = std::unique_ptr<AVCodecContext, CodecContextDeleter>;
using FramePtr = std::unique_ptr<AVFrame, FrameDeleter>;
using PacketPtr = std::unique_ptr<AVPacket, PacketDeleter>;
using SwsContextPtr = std::unique_ptr<SwsContext, SwsContextDeleter>;
using CodecParametersPtr = std::unique_ptr<AVCodecParameters, CodecParametersDeleter>;
using DictionaryPtr = std::unique_ptr<AVDictionary, DictionaryDeleter>;

// The text FFmpeg gives for an AVERROR code ("Invalid data found when processing input").
inline std::string error_string(int errnum) {
  char buffer[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(errnum, buffer, sizeof buffer);
  return buffer;
}

}  // namespace nelf::ffmpeg
