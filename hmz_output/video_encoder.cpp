#include "hmz_output/video_encoder.hpp"

#include "core/ffmpeg_raii.hpp"
#include "hmz_output/rgba_to_yuv.hpp"

#include <fmt/format.h>
#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string_view>
#include <system_error>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/audio_fifo.h>
#include <libavutil/opt.h>
#include <libavutil/pixdesc.h>
#include <libswresample/swresample.h>
#include <libswscale/swscale.h>
}

namespace nelf {

namespace {

using ffmpeg::CodecContextPtr;
using ffmpeg::FramePtr;
using ffmpeg::PacketPtr;
using ffmpeg::SwsContextPtr;
std::string av_error(int code) { return ffmpeg::error_string(code); }

struct SwrDeleter {
  void operator()(SwrContext* s) const { swr_free(&s); }
};
struct FifoDeleter {
  void operator()(AVAudioFifo* f) const { av_audio_fifo_free(f); }
};
// An output context owns its AVIOContext only once avio_open succeeded.
struct OutputContextDeleter {
  void operator()(AVFormatContext* f) const {
    if (f->pb && !(f->oformat->flags & AVFMT_NOFILE)) avio_closep(&f->pb);
    avformat_free_context(f);
  }
};

// The encoder behind a user-facing codec name.
const AVCodec* find_encoder(const std::string& name) {
  const char* actual = name == "h264" ? "libx264" : name == "hevc" || name == "h265" ? "libx265" : name.c_str();
  const AVCodec* codec = avcodec_find_encoder_by_name(actual);
  if (!codec || codec->type != AVMEDIA_TYPE_VIDEO)
    throw std::invalid_argument(
        fmt::format("--codec {}: no such video encoder in this FFmpeg (try h264, hevc, ffv1)", name));
  return codec;
}

// Whether every frame the encoder writes decodes to exactly what it was given (ffv1, utvideo,
// ffvhuff, png, ...); h264 is both lossy and lossless, so it is not one of them. Uncompressed
// video is left to the YUV formats: Matroska, the default container, refuses it in RGB.
bool is_lossless(const AVCodec* codec) {
  const AVCodecDescriptor* d = avcodec_descriptor_get(codec->id);
  return d && codec->id != AV_CODEC_ID_RAWVIDEO && (d->props & AV_CODEC_PROP_LOSSLESS) &&
         !(d->props & AV_CODEC_PROP_LOSSY);
}

// The pixel format to encode in, in order of preference. Lossless codecs keep RGB planes exactly.
// 4:2:0 needs even dimensions (libx264 refuses 4:2:0 at 2205 rows), so odd sizes use 4:4:4.
// Sources deeper than 8 bits keep 10 bits where the encoder can.
AVPixelFormat choose_pixel_format(const AVCodec* codec, int width, int height, int bits) {
  const bool even = width % 2 == 0 && height % 2 == 0;
  const bool deep = bits > 8;
  std::vector<AVPixelFormat> wanted;
  if (is_lossless(codec)) {
    if (deep) wanted.insert(wanted.end(), {AV_PIX_FMT_GBRP10, AV_PIX_FMT_GBRP16});
    wanted.insert(wanted.end(), {AV_PIX_FMT_BGR0, AV_PIX_FMT_GBRP, AV_PIX_FMT_RGB24});
  }
  if (deep && even) wanted.push_back(AV_PIX_FMT_YUV420P10);
  if (deep) wanted.push_back(AV_PIX_FMT_YUV444P10);
  if (even) wanted.push_back(AV_PIX_FMT_YUV420P);
  wanted.insert(wanted.end(), {AV_PIX_FMT_YUV444P, AV_PIX_FMT_GBRP, AV_PIX_FMT_RGB24, AV_PIX_FMT_BGR0});
  if (!codec->pix_fmts) return wanted.front();
  for (AVPixelFormat w : wanted)
    for (const AVPixelFormat* p = codec->pix_fmts; *p != AV_PIX_FMT_NONE; ++p)
      if (*p == w) return w;
  throw std::invalid_argument(
      fmt::format("--codec {}: no pixel format usable for a {}x{} frame", codec->name, width, height));
}

// Matroska holds any video FFmpeg has a Windows (BITMAPINFOHEADER) tag for, as ffmpeg itself writes
// it (V_MS/VFW/FOURCC: utvideo, ffvhuff, png, ...), though it reports only its native codecs at
// normal compliance.
bool container_holds(const AVOutputFormat* format, const AVCodec* codec) {
  if (avformat_query_codec(format, codec->id, FF_COMPLIANCE_NORMAL) == 1) return true;
  const AVCodecTag* const windows_tags[] = {avformat_get_riff_video_tags(), nullptr};
  return std::string_view(format->name).starts_with("matroska") && codec->type == AVMEDIA_TYPE_VIDEO &&
         av_codec_get_tag(windows_tags, codec->id) != 0;
}

bool is_rgb(AVPixelFormat f) { return av_pix_fmt_desc_get(f)->flags & AV_PIX_FMT_FLAG_RGB; }

std::filesystem::path temporary_path_for(const std::filesystem::path& output) {
  // Same directory (so the final rename is atomic), same extension (so the muxer is the same).
  return output.parent_path() /
         fmt::format(".{}.nelf-{}{}", output.stem().string(), ::getpid(), output.extension().string());
}

// Writes a packet whose timestamps are in `time_base`; the muxer rescales them to its stream's time
// base once its header has fixed it.
using PacketWriter = std::function<void(AVPacket*, AVRational time_base)>;

// An AAC track fed with samples of any format: they are converted (swresample) to the encoder's
// planar float, queued, and encoded in the encoder's frame size.
class AudioTrack {
 public:
  AudioTrack(AVFormatContext* muxer, int sample_rate, const AVChannelLayout& layout) {
    const AVCodec* codec = avcodec_find_encoder(AV_CODEC_ID_AAC);
    if (!codec) throw std::runtime_error("this FFmpeg has no AAC encoder");
    encoder_.reset(avcodec_alloc_context3(codec));
    encoder_->sample_rate = sample_rate;
    encoder_->sample_fmt = AV_SAMPLE_FMT_FLTP;
    // The encoder wants a native layout even when the source only says "N channels".
    av_channel_layout_default(&encoder_->ch_layout, layout.nb_channels);
    encoder_->bit_rate = 96000 * layout.nb_channels;
    encoder_->time_base = {1, sample_rate};
    if (muxer->oformat->flags & AVFMT_GLOBALHEADER) encoder_->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    if (const int r = avcodec_open2(encoder_.get(), codec, nullptr); r < 0)
      throw std::runtime_error(fmt::format("cannot open the AAC encoder: {}", av_error(r)));
    stream_ = avformat_new_stream(muxer, nullptr);
    avcodec_parameters_from_context(stream_->codecpar, encoder_.get());
    stream_->time_base = encoder_->time_base;
    fifo_.reset(av_audio_fifo_alloc(AV_SAMPLE_FMT_FLTP, layout.nb_channels, 4096));
    frame_.reset(av_frame_alloc());
    if (!fifo_ || !frame_) throw std::bad_alloc();
  }

  AVStream* stream() const { return stream_; }

  // Queues samples described by (format, layout, rate); converts them to the encoder's format.
  // `start_s` is the time of the first sample pushed, read on the first call only (later samples
  // follow on without gaps).
  void push(const uint8_t* const* data, int count, AVSampleFormat format, const AVChannelLayout& layout, int rate,
            double start_s, const PacketWriter& write) {
    if (!started_) {
      // The encoder's first packet is stamped `initial_padding` samples before its first input
      // sample (its priming). Matroska cannot start a track before 0, so the muxer would shift
      // every stream by it and the video would no longer start at 0. Instead the first
      // `initial_padding` samples are left out and the rest keep their time: the first packet is
      // stamped `start_s` and everything after plays in sync; what is lost is the first ~21 ms.
      skip_ = std::max(0, encoder_->initial_padding);
      next_pts_ = std::llround(start_s * encoder_->sample_rate) + skip_;
      started_ = true;
    }
    if (!resampler_ || format != in_format_ || rate != in_rate_) {
      SwrContext* raw = nullptr;
      AVChannelLayout in_layout{};  // FFmpeg 5.1 takes a non-const layout
      av_channel_layout_copy(&in_layout, &layout);
      const int set = swr_alloc_set_opts2(&raw, &encoder_->ch_layout, AV_SAMPLE_FMT_FLTP, encoder_->sample_rate,
                                          &in_layout, format, rate, 0, nullptr);
      av_channel_layout_uninit(&in_layout);
      if (set < 0 || swr_init(raw) < 0) {
        swr_free(&raw);
        throw std::runtime_error("cannot set up the audio conversion");
      }
      resampler_.reset(raw);
      in_format_ = format;
      in_rate_ = rate;
    }
    const int capacity = static_cast<int>(swr_get_out_samples(resampler_.get(), count));
    std::vector<std::vector<float>> planes(static_cast<std::size_t>(encoder_->ch_layout.nb_channels),
                                           std::vector<float>(static_cast<std::size_t>(std::max(capacity, 1))));
    std::vector<uint8_t*> out;
    for (auto& p : planes) out.push_back(reinterpret_cast<uint8_t*>(p.data()));
    const int converted = swr_convert(resampler_.get(), out.data(), capacity, const_cast<const uint8_t**>(data), count);
    if (converted < 0) throw std::runtime_error("audio conversion failed");
    const int skipped = std::min(skip_, converted);
    skip_ -= skipped;
    for (auto& plane : out) plane += static_cast<std::ptrdiff_t>(skipped) * static_cast<std::ptrdiff_t>(sizeof(float));
    av_audio_fifo_write(fifo_.get(), reinterpret_cast<void**>(out.data()), converted - skipped);
    encode_available(false, write);
  }

  void flush(const PacketWriter& write) {
    encode_available(true, write);
    drain(true, write);
  }

 private:
  void encode_available(bool final_block, const PacketWriter& write) {
    const int frame_size = encoder_->frame_size > 0 ? encoder_->frame_size : 1024;
    while (av_audio_fifo_size(fifo_.get()) >= frame_size || (final_block && av_audio_fifo_size(fifo_.get()) > 0)) {
      const int n = std::min(frame_size, av_audio_fifo_size(fifo_.get()));
      av_frame_unref(frame_.get());
      frame_->nb_samples = n;
      frame_->format = AV_SAMPLE_FMT_FLTP;
      frame_->sample_rate = encoder_->sample_rate;
      av_channel_layout_copy(&frame_->ch_layout, &encoder_->ch_layout);
      if (av_frame_get_buffer(frame_.get(), 0) < 0) throw std::bad_alloc();
      av_audio_fifo_read(fifo_.get(), reinterpret_cast<void**>(frame_->data), n);
      frame_->pts = next_pts_;
      next_pts_ += n;
      if (const int r = avcodec_send_frame(encoder_.get(), frame_.get()); r < 0)
        throw std::runtime_error(fmt::format("audio encoding failed: {}", av_error(r)));
      drain(false, write);
    }
  }

  void drain(bool flush, const PacketWriter& write) {
    if (flush) avcodec_send_frame(encoder_.get(), nullptr);
    PacketPtr packet(av_packet_alloc());
    for (;;) {
      const int r = avcodec_receive_packet(encoder_.get(), packet.get());
      if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return;
      if (r < 0) throw std::runtime_error(fmt::format("audio encoding failed: {}", av_error(r)));
      packet->stream_index = stream_->index;
      write(packet.get(), encoder_->time_base);
    }
  }

  CodecContextPtr encoder_;
  std::unique_ptr<AVAudioFifo, FifoDeleter> fifo_;
  std::unique_ptr<SwrContext, SwrDeleter> resampler_;
  FramePtr frame_;
  AVStream* stream_ = nullptr;
  AVSampleFormat in_format_ = AV_SAMPLE_FMT_NONE;
  int in_rate_ = 0;
  bool started_ = false;
  int skip_ = 0;  // priming samples still to leave out
  int64_t next_pts_ = 0;
};

// A source audio stream the container cannot hold as it is: decoded and re-encoded as AAC.
struct ReencodedStream {
  CodecContextPtr decoder;
  FramePtr frame{av_frame_alloc()};
  std::unique_ptr<AudioTrack> track;
};

// A decoded subtitle event, freed with what the decoder allocated in it.
struct DecodedSubtitle {
  AVSubtitle subtitle{};
  DecodedSubtitle() = default;
  DecodedSubtitle(const DecodedSubtitle&) = delete;
  DecodedSubtitle& operator=(const DecodedSubtitle&) = delete;
  ~DecodedSubtitle() { avsubtitle_free(&subtitle); }
};

// A text subtitle stream (SubRip, ASS, WebVTT) for a container that holds only its own text
// format (MP4, MOV: mov_text, the tx3g of QuickTime): each event is decoded to its ASS text and
// encoded again, keeping its time. FFmpeg's own decoders and mov_text encoder do it, as the
// ffmpeg CLI does for `-c:s mov_text`, so styling tags are mapped as it maps them.
class TextSubtitleTrack {
 public:
  // Null when FFmpeg lacks the decoder or the encoder.
  static std::unique_ptr<TextSubtitleTrack> open(AVFormatContext* muxer, const CarriedStream& in) {
    const AVCodec* decoder = avcodec_find_decoder(in.codec->codec_id);
    const AVCodec* encoder = avcodec_find_encoder(AV_CODEC_ID_MOV_TEXT);
    if (!decoder || !encoder) return nullptr;
    auto track = std::make_unique<TextSubtitleTrack>();
    track->decoder_.reset(avcodec_alloc_context3(decoder));
    if (!track->decoder_ || avcodec_parameters_to_context(track->decoder_.get(), in.codec.get()) < 0) return nullptr;
    track->decoder_->pkt_timebase = in.time_base;
    if (avcodec_open2(track->decoder_.get(), decoder, nullptr) < 0) return nullptr;
    track->encoder_.reset(avcodec_alloc_context3(encoder));
    if (!track->encoder_) return nullptr;
    track->encoder_->time_base = in.time_base;
    // The encoder reads the styles the decoder's events refer to from the decoder's ASS header.
    if (const AVCodecContext& d = *track->decoder_; d.subtitle_header_size > 0) {
      track->encoder_->subtitle_header = static_cast<uint8_t*>(av_mallocz(d.subtitle_header_size + 1));
      if (!track->encoder_->subtitle_header) throw std::bad_alloc();
      std::copy_n(d.subtitle_header, d.subtitle_header_size, track->encoder_->subtitle_header);
      track->encoder_->subtitle_header_size = d.subtitle_header_size;
    }
    if (avcodec_open2(track->encoder_.get(), encoder, nullptr) < 0) return nullptr;
    track->stream_ = avformat_new_stream(muxer, nullptr);
    if (!track->stream_) throw std::bad_alloc();
    avcodec_parameters_from_context(track->stream_->codecpar, track->encoder_.get());
    track->stream_->time_base = in.time_base;
    return track;
  }

  AVStream* stream() const { return stream_; }

  // One source event; a damaged one is skipped.
  void write(const AVPacket& in, const PacketWriter& write) {
    DecodedSubtitle decoded;
    int got = 0;
    AVPacket* source = const_cast<AVPacket*>(&in);  // FFmpeg 5.1 takes a non-const packet
    if (avcodec_decode_subtitle2(decoder_.get(), &decoded.subtitle, &got, source) < 0 || !got) return;
    std::vector<uint8_t> buffer(std::max<std::size_t>(1024, static_cast<std::size_t>(in.size) * 4 + 64));
    const int size =
        avcodec_encode_subtitle(encoder_.get(), buffer.data(), static_cast<int>(buffer.size()), &decoded.subtitle);
    if (size <= 0) return;
    PacketPtr out(av_packet_alloc());
    if (!out || av_new_packet(out.get(), size) < 0) throw std::bad_alloc();
    std::copy_n(buffer.data(), size, out->data);
    out->pts = in.pts;
    out->dts = in.pts;
    out->duration = in.duration;
    out->flags |= AV_PKT_FLAG_KEY;
    out->stream_index = stream_->index;
    write(out.get(), encoder_->time_base);
  }

 private:
  CodecContextPtr decoder_, encoder_;
  AVStream* stream_ = nullptr;
};

bool is_text_subtitle(AVCodecID id) {
  const AVCodecDescriptor* descriptor = avcodec_descriptor_get(id);
  return descriptor && (descriptor->props & AV_CODEC_PROP_TEXT_SUB) != 0;
}

}  // namespace

struct VideoEncoder::State {
  std::filesystem::path output, temporary;
  std::unique_ptr<AVFormatContext, OutputContextDeleter> muxer;
  CodecContextPtr encoder;
  FramePtr frame;
  PacketPtr packet{av_packet_alloc()};
  SwsContextPtr sws;
  int sws_bits = 0;
  AVStream* video_stream = nullptr;
  std::vector<int> stream_map;  // source stream index -> output stream index, -1 when dropped
  std::vector<AVRational> source_time_bases;
  std::string codec_name, pixel_format_name;
  bool header_written = false, finished = false;
  std::unique_ptr<AudioTrack> generated_audio;  // add_audio_track()
  int generated_channels = 0, generated_rate = 0;
  std::vector<std::unique_ptr<ReencodedStream>> reencoded;       // by source stream index, null when copied/dropped
  std::vector<std::unique_ptr<TextSubtitleTrack>> retimed_text;  // by source stream index, null unless mov_text
  PacketWriter writer = [this](AVPacket* p, AVRational time_base) { write(p, time_base); };
  int64_t last_pts = AV_NOPTS_VALUE;

  void drain(bool flush) {
    if (flush) avcodec_send_frame(encoder.get(), nullptr);
    for (;;) {
      const int r = avcodec_receive_packet(encoder.get(), packet.get());
      if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return;
      if (r < 0) throw std::runtime_error(fmt::format("{}: encoding failed: {}", output.string(), av_error(r)));
      packet->stream_index = video_stream->index;
      write(packet.get(), encoder->time_base);
    }
  }

  // The header goes out with the first packet, so that tracks can still be added after construction.
  void ensure_header() {
    if (header_written) return;
    if (const int r = avformat_write_header(muxer.get(), nullptr); r < 0)
      throw std::runtime_error(
          fmt::format("{}: cannot start the {} file: {}", output.string(), muxer->oformat->name, av_error(r)));
    header_written = true;
  }

  // `p`'s timestamps are in `time_base`. They are rescaled only after the header is written:
  // avformat_write_header may change a stream's time base (Matroska: 1/1000, MPEG-TS: 1/90000), and
  // a packet rescaled to the time base asked for before it would be read in the one set after it.
  void write(AVPacket* p, AVRational time_base) {
    ensure_header();
    av_packet_rescale_ts(p, time_base, muxer->streams[p->stream_index]->time_base);
    const int r = av_interleaved_write_frame(muxer.get(), p);
    if (r < 0)
      throw std::runtime_error(fmt::format("{}: cannot write: {}", output.string(),
                                           r == AVERROR(ENOSPC) ? "no space left on device" : av_error(r)));
  }
};

VideoEncoder::VideoEncoder(const std::filesystem::path& output, int width, int height, int frame_rate_num,
                           int frame_rate_den, const EncoderSettings& settings, const CarriedStreamLayout* carried)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.output = output;
  std::error_code ec;
  // symlink_status: a dangling symlink is an existing name too (finish() would replace it).
  if (std::filesystem::exists(std::filesystem::symlink_status(output, ec)) && !settings.overwrite)
    throw std::runtime_error(fmt::format("{}: already exists; pass -y to overwrite", output.string()));
  const AVOutputFormat* format = av_guess_format(nullptr, output.filename().c_str(), nullptr);
  if (!format)
    throw std::invalid_argument(
        fmt::format("{}: unknown output format; use an extension such as .mkv, .mp4 or .mov", output.string()));
  const AVCodec* codec = find_encoder(settings.codec);
  if (!container_holds(format, codec))
    throw std::invalid_argument(fmt::format(
        "{}: the {} container cannot hold {} video ({})", output.string(), format->name, codec->name,
        container_holds(av_guess_format("matroska", nullptr, nullptr), codec) ? "use .mkv" : "choose another --codec"));

  s.temporary = temporary_path_for(output);
  AVFormatContext* raw = nullptr;
  if (avformat_alloc_output_context2(&raw, format, nullptr, s.temporary.c_str()) < 0 || !raw)
    throw std::runtime_error(fmt::format("{}: cannot set up the {} muxer", output.string(), format->name));
  s.muxer.reset(raw);

  // Video encoder.
  s.encoder.reset(avcodec_alloc_context3(codec));
  AVCodecContext& c = *s.encoder;
  c.width = width;
  c.height = height;
  c.sample_aspect_ratio = {1, 1};
  c.framerate = {frame_rate_num, frame_rate_den};
  c.time_base = {1, 90000};  // fine enough for any frame rate, keeps variable frame timing
  c.pix_fmt = choose_pixel_format(codec, width, height, settings.bits);
  c.thread_count = 0;
  if (is_rgb(c.pix_fmt)) {
    c.color_range = AVCOL_RANGE_JPEG;
    c.colorspace = AVCOL_SPC_RGB;
  } else {
    c.color_range = AVCOL_RANGE_MPEG;
    c.colorspace = AVCOL_SPC_BT709;
  }
  c.color_primaries = AVCOL_PRI_BT709;
  c.color_trc = AVCOL_TRC_BT709;
  if (s.muxer->oformat->flags & AVFMT_GLOBALHEADER) c.flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  if (codec->id == AV_CODEC_ID_H264 || codec->id == AV_CODEC_ID_HEVC) {
    av_opt_set(c.priv_data, "preset", settings.preset.c_str(), 0);
    av_opt_set_double(c.priv_data, "crf", settings.crf.value_or(18), 0);
    if (codec->id == AV_CODEC_ID_HEVC) av_opt_set(c.priv_data, "x265-params", "log-level=error", 0);
  } else if (settings.crf) {
    throw std::invalid_argument(fmt::format("--crf applies to h264 and hevc, not {}", codec->name));
  }
  if (const int r = avcodec_open2(&c, codec, nullptr); r < 0)
    throw std::runtime_error(fmt::format("{}: cannot open the {} encoder for {}x{}: {}", output.string(), codec->name,
                                         width, height, av_error(r)));
  s.codec_name = codec->name;
  s.pixel_format_name = av_get_pix_fmt_name(c.pix_fmt);

  s.video_stream = avformat_new_stream(s.muxer.get(), nullptr);
  avcodec_parameters_from_context(s.video_stream->codecpar, &c);
  s.video_stream->time_base = c.time_base;
  s.video_stream->avg_frame_rate = c.framerate;

  // Carry the source's audio and subtitle streams, chapters and metadata where the container takes them.
  if (carried) {
    int last_index = -1;
    for (const CarriedStream& in : carried->streams) last_index = std::max(last_index, in.index);
    const auto slots = static_cast<std::size_t>(last_index + 1);
    s.stream_map.assign(slots, -1);
    s.source_time_bases.assign(slots, AVRational{0, 1});
    int subtitles = 0;
    for (const CarriedStream& in : carried->streams) {
      const auto i = static_cast<std::size_t>(in.index);
      s.source_time_bases[i] = in.time_base;
      const AVMediaType type = in.codec->codec_type;
      if (type == AVMEDIA_TYPE_AUDIO && !settings.audio) continue;
      if (type != AVMEDIA_TYPE_AUDIO && type != AVMEDIA_TYPE_SUBTITLE) continue;
      // A player draws a default subtitle track flat over the whole frame, across the elemental
      // images of the right eye's half too: carried tracks are there to be chosen, not shown.
      const int disposition = type == AVMEDIA_TYPE_SUBTITLE ? in.disposition & ~AV_DISPOSITION_DEFAULT : in.disposition;
      const bool holds = avformat_query_codec(format, in.codec->codec_id, FF_COMPLIANCE_NORMAL) == 1;
      if (!holds && type == AVMEDIA_TYPE_SUBTITLE && is_text_subtitle(in.codec->codec_id) &&
          avformat_query_codec(format, AV_CODEC_ID_MOV_TEXT, FF_COMPLIANCE_NORMAL) == 1) {
        if (auto text = TextSubtitleTrack::open(s.muxer.get(), in)) {
          av_dict_copy(&text->stream()->metadata, in.metadata.get(), 0);
          text->stream()->disposition = disposition;
          s.stream_map[i] = text->stream()->index;
          s.retimed_text.resize(slots);
          s.retimed_text[i] = std::move(text);
          ++subtitles;
          continue;
        }
      }
      if (!holds) {
        if (type == AVMEDIA_TYPE_AUDIO) {
          // The container cannot hold this audio codec: decode it and re-encode it as AAC.
          s.reencoded.resize(slots);
          auto re = std::make_unique<ReencodedStream>();
          const AVCodec* decoder = avcodec_find_decoder(in.codec->codec_id);
          if (decoder) {
            re->decoder.reset(avcodec_alloc_context3(decoder));
            avcodec_parameters_to_context(re->decoder.get(), in.codec.get());
            re->decoder->pkt_timebase = in.time_base;
          }
          if (decoder && avcodec_open2(re->decoder.get(), decoder, nullptr) >= 0) {
            re->track = std::make_unique<AudioTrack>(s.muxer.get(), re->decoder->sample_rate, re->decoder->ch_layout);
            av_dict_copy(&re->track->stream()->metadata, in.metadata.get(), 0);
            re->track->stream()->disposition = in.disposition;
            s.stream_map[i] = re->track->stream()->index;
            s.reencoded[i] = std::move(re);
            continue;
          }
        }
        fmt::print(stderr, "nelf: warning: {} stream {} ({}) cannot be stored in {}: dropped (use .mkv to keep it)\n",
                   av_get_media_type_string(type), in.index, avcodec_get_name(in.codec->codec_id), format->name);
        continue;
      }
      AVStream* out = avformat_new_stream(s.muxer.get(), nullptr);
      avcodec_parameters_copy(out->codecpar, in.codec.get());
      out->codecpar->codec_tag = 0;
      out->time_base = in.time_base;
      out->disposition = disposition;
      av_dict_copy(&out->metadata, in.metadata.get(), 0);  // language tags, titles
      s.stream_map[i] = out->index;
      if (type == AVMEDIA_TYPE_SUBTITLE) ++subtitles;
    }
    // The MP4 muxer enables the first track of each kind when none is default (FFmpeg 5.1's
    // enable_tracks), and players show an enabled subtitle track.
    const bool enables_first = avformat_query_codec(format, AV_CODEC_ID_MOV_TEXT, FF_COMPLIANCE_NORMAL) == 1;
    if (subtitles > 0)
      fmt::print(stderr,
                 "nelf: {} subtitle stream{} carried without the default flag: a player would draw {} flat across "
                 "the elemental images of both eyes{}\n",
                 subtitles, subtitles == 1 ? "" : "s", subtitles == 1 ? "it" : "them",
                 enables_first
                     ? fmt::format(" ({} enables the first one all the same; .mkv keeps them off)", format->name)
                     : "");
    av_dict_copy(&s.muxer->metadata, carried->metadata.get(), 0);
    std::vector<const CarriedChapter*> chapters;
    for (const CarriedChapter& in : carried->chapters) {
      // At output time already; --duration ends them at the latest.
      const double unit = av_q2d(in.time_base);
      if (settings.carried_end_s && static_cast<double>(in.start) * unit >= *settings.carried_end_s - 1e-6) continue;
      chapters.push_back(&in);
    }
    if (!chapters.empty()) {
      s.muxer->chapters = static_cast<AVChapter**>(av_calloc(chapters.size(), sizeof(AVChapter*)));
      if (!s.muxer->chapters) throw std::bad_alloc();
      for (const CarriedChapter* chapter : chapters) {
        const CarriedChapter& in = *chapter;
        std::int64_t end = in.end;
        if (settings.carried_end_s)
          end = std::min(end, static_cast<std::int64_t>(std::llround(*settings.carried_end_s / av_q2d(in.time_base))));
        auto* out = static_cast<AVChapter*>(av_mallocz(sizeof(AVChapter)));
        if (!out) throw std::bad_alloc();
        *out = {in.id, in.time_base, in.start, end, nullptr};
        av_dict_copy(&out->metadata, in.metadata.get(), 0);
        s.muxer->chapters[s.muxer->nb_chapters++] = out;
      }
    }
  }

  if (!(format->flags & AVFMT_NOFILE)) {
    if (const int r = avio_open(&s.muxer->pb, s.temporary.c_str(), AVIO_FLAG_WRITE); r < 0)
      throw std::runtime_error(fmt::format("{}: cannot write here: {}", output.string(), av_error(r)));
  }

  s.frame.reset(av_frame_alloc());
  s.frame->format = c.pix_fmt;
  s.frame->width = width;
  s.frame->height = height;
  s.frame->color_range = c.color_range;
  s.frame->colorspace = c.colorspace;
  s.frame->color_primaries = c.color_primaries;
  s.frame->color_trc = c.color_trc;
  if (av_frame_get_buffer(s.frame.get(), 0) < 0) throw std::bad_alloc();
}

VideoEncoder::~VideoEncoder() {
  if (!state_ || state_->finished) return;
  // Unfinished: close the file and remove it, leaving nothing half-written behind.
  state_->muxer.reset();
  std::error_code ec;
  std::filesystem::remove(state_->temporary, ec);
}

// RGBA (8 or 16 bits) to the encoder's pixel format through swscale, with the colour matrix the
// stream is tagged with.
void VideoEncoder::convert_with_swscale(State& s, const PackedFrame& in) {
  AVCodecContext& c = *s.encoder;
  if (!s.sws || s.sws_bits != in.bits) {
    const AVPixelFormat source_format = in.bits > 8 ? AV_PIX_FMT_RGBA64LE : AV_PIX_FMT_RGBA;
    s.sws.reset(sws_getContext(c.width, c.height, source_format, c.width, c.height, c.pix_fmt,
                               SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, nullptr, nullptr, nullptr));
    if (!s.sws) throw std::runtime_error("cannot set up the RGB to YUV conversion");
    if (!is_rgb(c.pix_fmt)) {
      // RGB → BT.709 limited-range YUV: the matrix the stream is tagged with.
      const int* bt709 = sws_getCoefficients(SWS_CS_ITU709);
      sws_setColorspaceDetails(s.sws.get(), bt709, 1, bt709, 0, 0, 1 << 16, 1 << 16);
    }
    s.sws_bits = in.bits;
  }
  const uint8_t* planes[1] = {in.rgba.data()};
  const int strides[1] = {in.width * 4 * (in.bits > 8 ? 2 : 1)};
  sws_scale(s.sws.get(), planes, strides, 0, in.height, s.frame->data, s.frame->linesize);
}

void VideoEncoder::write_video(const PackedFrame& in) {
  State& s = *state_;
  AVCodecContext& c = *s.encoder;
  if (in.width != c.width || in.height != c.height)
    throw std::logic_error(
        fmt::format("VideoEncoder: frame is {}x{}, stream is {}x{}", in.width, in.height, c.width, c.height));
  if (av_frame_make_writable(s.frame.get()) < 0) throw std::bad_alloc();
  if (in.bits == 8 && c.pix_fmt == AV_PIX_FMT_YUV420P) {
    // The common case (8-bit 4:2:0 for libx264 & co.): the own conversion, ~4× cheaper than
    // swscale's generic path for RGBA input (hmz_output/rgba_to_yuv.hpp).
    rgba_to_yuv420_bt709(in.rgba.data(), static_cast<std::ptrdiff_t>(in.width) * 4, in.width, in.height,
                         {s.frame->data[0], s.frame->data[1], s.frame->data[2], s.frame->linesize[0],
                          s.frame->linesize[1], s.frame->linesize[2]});
  } else {
    convert_with_swscale(s, in);
  }
  int64_t pts = llround(in.pts_seconds * c.time_base.den / c.time_base.num);
  if (s.last_pts != AV_NOPTS_VALUE && pts <= s.last_pts) pts = s.last_pts + 1;  // strictly increasing
  s.last_pts = pts;
  s.frame->pts = pts;
  if (const int r = avcodec_send_frame(&c, s.frame.get()); r < 0)
    throw std::runtime_error(fmt::format("{}: encoding failed: {}", s.output.string(), av_error(r)));
  s.drain(false);
}

void VideoEncoder::write_source_packet(AVPacket* packet, int source_stream) {
  State& s = *state_;
  if (source_stream < 0 || source_stream >= static_cast<int>(s.stream_map.size())) return;
  const int out_index = s.stream_map[static_cast<std::size_t>(source_stream)];
  if (out_index < 0) return;
  if (static_cast<std::size_t>(source_stream) < s.reencoded.size() &&
      s.reencoded[static_cast<std::size_t>(source_stream)]) {
    ReencodedStream& re = *s.reencoded[static_cast<std::size_t>(source_stream)];
    if (avcodec_send_packet(re.decoder.get(), packet) < 0) return;  // a damaged audio packet is skipped
    while (avcodec_receive_frame(re.decoder.get(), re.frame.get()) >= 0) {
      // The packets were shifted to output time, so the decoded frames' timestamps are output time.
      const int64_t pts = re.frame->best_effort_timestamp;
      const double start_s = pts == AV_NOPTS_VALUE ? 0.0 : static_cast<double>(pts) * av_q2d(re.decoder->pkt_timebase);
      re.track->push(re.frame->extended_data, re.frame->nb_samples, static_cast<AVSampleFormat>(re.frame->format),
                     re.frame->ch_layout, re.frame->sample_rate, start_s, s.writer);
      av_frame_unref(re.frame.get());
    }
    return;
  }
  if (static_cast<std::size_t>(source_stream) < s.retimed_text.size() &&
      s.retimed_text[static_cast<std::size_t>(source_stream)]) {
    s.retimed_text[static_cast<std::size_t>(source_stream)]->write(*packet, s.writer);
    return;
  }
  packet->stream_index = out_index;
  packet->pos = -1;
  s.write(packet, s.source_time_bases[static_cast<std::size_t>(source_stream)]);
}

void VideoEncoder::add_audio_track(int sample_rate, int channels) {
  State& s = *state_;
  if (s.header_written) throw std::logic_error("VideoEncoder::add_audio_track after the header was written");
  AVChannelLayout layout;
  av_channel_layout_default(&layout, channels);
  s.generated_audio = std::make_unique<AudioTrack>(s.muxer.get(), sample_rate, layout);
  s.generated_channels = channels;
  s.generated_rate = sample_rate;
}

void VideoEncoder::write_audio(const float* interleaved, int sample_count) {
  State& s = *state_;
  if (!s.generated_audio) throw std::logic_error("VideoEncoder::write_audio without add_audio_track");
  const uint8_t* data[1] = {reinterpret_cast<const uint8_t*>(interleaved)};
  AVChannelLayout layout;
  av_channel_layout_default(&layout, s.generated_channels);
  s.generated_audio->push(data, sample_count, AV_SAMPLE_FMT_FLT, layout, s.generated_rate, 0.0, s.writer);
}

void VideoEncoder::finish() {
  State& s = *state_;
  s.ensure_header();
  s.drain(true);
  if (s.generated_audio) s.generated_audio->flush(s.writer);
  for (auto& re : s.reencoded)
    if (re) re->track->flush(s.writer);
  if (const int r = av_write_trailer(s.muxer.get()); r < 0)
    throw std::runtime_error(fmt::format("{}: cannot finish the file: {}", s.output.string(), av_error(r)));
  if (s.muxer->pb) {
    if (const int r = avio_closep(&s.muxer->pb); r < 0)
      throw std::runtime_error(fmt::format("{}: cannot write: {}", s.output.string(), av_error(r)));
  }
  std::error_code ec;
  std::filesystem::rename(s.temporary, s.output, ec);
  if (ec)
    throw std::runtime_error(
        fmt::format("{}: cannot rename the finished file into place: {}", s.output.string(), ec.message()));
  s.finished = true;
}

const std::string& VideoEncoder::codec_name() const { return state_->codec_name; }
const std::string& VideoEncoder::pixel_format_name() const { return state_->pixel_format_name; }

std::vector<int> VideoEncoder::carried_streams() const {
  std::vector<int> carried;
  for (std::size_t i = 0; i < state_->stream_map.size(); ++i)
    if (state_->stream_map[i] >= 0) carried.push_back(static_cast<int>(i));
  return carried;
}

}  // namespace nelf
