#include "inputs/video_source.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string_view>

#include "core/ffmpeg_raii.hpp"
#include "inputs/ffmpeg_input.hpp"
#include "inputs/video_pixels.hpp"
#include "inputs/yuv_block_means.hpp"

extern "C" {
#include <libavdevice/avdevice.h>
#include <libavutil/display.h>
#include <libavutil/imgutils.h>
#include <libavutil/pixdesc.h>
}

namespace nelf {

std::string_view to_string(ColorMatrix matrix) {
  switch (matrix) {
    case ColorMatrix::bt601:
      return "bt601";
    case ColorMatrix::bt709:
      return "bt709";
    case ColorMatrix::bt2020:
      return "bt2020";
    case ColorMatrix::smpte240m:
      return "smpte240m";
    case ColorMatrix::fcc:
      return "fcc";
    case ColorMatrix::rgb:
      return "rgb";
  }
  return "unknown";
}

std::string_view to_string(ColorRange range) { return range == ColorRange::full ? "full" : "limited"; }

const void* VideoFrame::pixels() const {
  if (!reduced.empty()) return nullptr;
  return bits > 8 ? static_cast<const void*>(rgba16.data()) : static_cast<const void*>(rgba8.data());
}

float VideoFrame::channel(int x, int y, int c) const {
  const std::size_t i =
      (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 4 +
      static_cast<std::size_t>(c);
  return bits > 8 ? static_cast<float>(rgba16[i]) / 65535.f : static_cast<float>(rgba8[i]) / 255.f;
}

Image VideoFrame::to_image() const {
  if (!reduced.empty()) throw std::logic_error("VideoFrame::to_image: the frame was delivered as reduced regions");
  Image image(width, height);
  float* out = image.data();
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4;
  if (bits > 8) {
    for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(rgba16[i]) / 65535.f;
  } else {
    for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(rgba8[i]) / 255.f;
  }
  return image;
}

namespace {

using namespace nelf::ffmpeg;

double rational_or_zero(AVRational r) { return r.num > 0 && r.den > 0 ? av_q2d(r) : 0.0; }

using namespace video_pixels;

}  // namespace

struct VideoSource::Impl {
  VideoInfo info;
  VideoSourceOptions options;
  InputGuard network;  // before `format`: the context points at it while it lives
  FormatContextPtr format;
  CodecContextPtr codec;
  AVStream* stream = nullptr;
  PacketPtr packet;
  FramePtr frame;
  FramePtr converted;
  FramePtr last;  // a reference to the frame delivered last (convert_last)
  SwsContextPtr sws;
  // reduce_regions(): the regions, and a converter for their size (one size for all of them).
  std::vector<ReducedRegion> regions;
  int reduce_max_bits = 16;
  SwsContextPtr reduce_sws;
  int reduce_format = -1, reduce_colorspace = -1, reduce_full_range = -1;
  // What `sws` was built for; a change mid-stream (resolution switch) rebuilds it.
  int sws_width = 0, sws_height = 0, sws_format = -1, sws_colorspace = -1, sws_full_range = -1;
  bool draining = false;
  bool finished = false;
  int consecutive_errors = 0;
  double last_pts_s = 0.0;
  double last_pts_s_before = 0.0;  // last_pts_s before the last frame (convert_last converts it again)
  std::int64_t frames_out = 0;
  DecodeStats stats;
  std::optional<StereoMetadata> frame_stereo;
  std::optional<double> pending_after_seek;
  bool seeked = false;  // frames before this time (s) are skipped after seek()
  // The timeline actually read: the latest end (pts + duration) of a packet of any stream, and the
  // first and last timestamps of the decoded video frames (count_missing_frames).
  std::optional<double> packets_end_s;
  std::optional<double> first_frame_s, last_frame_s;
  int multiview_packets_left = 64;  // packets still to look at for a second view's NAL units

  [[noreturn]] void fail(const std::string& what) const { throw VideoError(fmt::format("{}: {}", info.path, what)); }

  // Refuses frames over --max-pixels (core/pixel_limit.hpp); `where` says which (" in the stream").
  void check_pixel_limit(int width, int height, std::string_view where) const {
    if (const auto problem = pixel_limit_problem(width, height, options.max_pixels))
      fail(fmt::format("video frames{}: {}", where, *problem));
  }

  void open(const std::string& path) {
    info.path = path;
    const AVInputFormat* device = nullptr;
    if (!options.device.empty()) {
      static const bool registered = (avdevice_register_all(), true);
      (void)registered;
      device = av_find_input_format(options.device.c_str());
      if (device == nullptr || device->priv_class == nullptr || !AV_IS_INPUT_DEVICE(device->priv_class->category))
        throw VideoError(
            fmt::format("{}: FFmpeg has no input device '{}' (ffmpeg -devices lists them)", path, options.device));
      info.live = true;
    } else if (!is_url(path)) {
      std::error_code ec;
      const auto status = std::filesystem::status(path, ec);
      if (!std::filesystem::exists(status)) fail("no such file");
      if (std::filesystem::is_directory(status)) fail("is a directory, not a media file");
    }

    // Playlists (HLS, concat, …) can otherwise make FFmpeg fetch URLs (DESIGN.md §11).
    network.allow_network = options.allow_network;
    std::vector<std::string> unknown;
    const int opened = open_input(format, path, network, device, options.device_options, &unknown);
    if (const auto stopped = guard_stop(path, network)) throw VideoError(*stopped);
    if (!unknown.empty())
      throw VideoError(
          fmt::format("{}: the {} device has no option {} (--device-option; ffmpeg -h demuxer={} lists them)", path,
                      options.device, unknown.front(), options.device));
    if (opened < 0) {
      if (opened == AVERROR_INVALIDDATA) fail("not a media file FFmpeg can read");
      if (opened == AVERROR(EACCES)) fail("permission denied");
      fail(fmt::format("cannot open: {}", error_string(opened)));
    }
    info.container = format->iformat->name;
    // FFmpeg opens any text file as "tty" (ANSI art) video; a text file is never meant as content.
    if (info.container == "tty") fail("not a media file (it looks like text)");

    // Frame sizes the container's header declares (Matroska, MP4, Y4M) are checked before probing,
    // which decodes the first frames. The decoders probing opens get the pixel limit too, so that
    // a stream whose size only its frames tell (a PNG, MPEG-TS) is not decoded over it either.
    for (unsigned i = 0; i < format->nb_streams; ++i) {
      const AVStream* declared = format->streams[i];
      if (declared->codecpar->codec_type == AVMEDIA_TYPE_VIDEO &&
          (declared->disposition & AV_DISPOSITION_ATTACHED_PIC) == 0)
        check_pixel_limit(declared->codecpar->width, declared->codecpar->height, "");
    }
    const std::string max_pixels = std::to_string(options.max_pixels);
    std::vector<AVDictionary*> probe_options(format->nb_streams, nullptr);
    for (AVDictionary*& o : probe_options) av_dict_set(&o, "max_pixels", max_pixels.c_str(), 0);
    const int found = find_stream_info(format.get(), network, probe_options.empty() ? nullptr : probe_options.data());
    for (AVDictionary*& o : probe_options) av_dict_free(&o);
    // Some demuxers open what a playlist names only when probing the streams.
    if (const auto stopped = guard_stop(path, network)) throw VideoError(*stopped);
    if (found < 0) fail(fmt::format("not a readable media file: {}", error_string(found)));

    for (unsigned i = 0; i < format->nb_streams; ++i) {
      const AVCodecParameters& stream_codec = *format->streams[i]->codecpar;
      if (stream_codec.codec_type == AVMEDIA_TYPE_AUDIO) ++info.audio_streams;
      // An MPEG-TS MVC sub-stream is a video stream of its own beside the base view's.
      if (stream_codec.codec_type == AVMEDIA_TYPE_VIDEO && info.multiview == Multiview::none)
        info.multiview = multiview_from_codec(stream_codec);
    }

    const AVCodec* decoder = nullptr;
    int best = av_find_best_stream(format.get(), AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
    // Cover art (an audio file's picture) is a "video" stream of one frame: never the content.
    auto is_moving_video = [](const AVStream* candidate) {
      return candidate->codecpar->codec_type == AVMEDIA_TYPE_VIDEO &&
             (candidate->disposition & AV_DISPOSITION_ATTACHED_PIC) == 0;
    };
    if (best >= 0 && !is_moving_video(format->streams[best])) {
      best = AVERROR_STREAM_NOT_FOUND;
      decoder = nullptr;
      for (unsigned i = 0; i < format->nb_streams && decoder == nullptr; ++i) {
        if (!is_moving_video(format->streams[i])) continue;
        decoder = avcodec_find_decoder(format->streams[i]->codecpar->codec_id);
        best = decoder != nullptr ? static_cast<int>(i) : AVERROR_DECODER_NOT_FOUND;
      }
    }
    if (best == AVERROR_STREAM_NOT_FOUND) {
      bool has_cover = false;
      for (unsigned i = 0; i < format->nb_streams; ++i)
        if ((format->streams[i]->disposition & AV_DISPOSITION_ATTACHED_PIC) != 0) has_cover = true;
      std::string only;
      if (info.audio_streams > 0)
        only = fmt::format("{} audio stream{}", info.audio_streams, info.audio_streams == 1 ? "" : "s");
      if (has_cover) only += only.empty() ? "a cover picture" : " and a cover picture";
      fail(only.empty() ? std::string("no video stream") : fmt::format("no video stream (only {})", only));
    }
    if (best == AVERROR_DECODER_NOT_FOUND) {
      const AVStream* first_video = nullptr;
      for (unsigned i = 0; i < format->nb_streams && first_video == nullptr; ++i)
        if (is_moving_video(format->streams[i])) first_video = format->streams[i];
      const AVCodecID id = first_video != nullptr ? first_video->codecpar->codec_id : AV_CODEC_ID_NONE;
      if (id == AV_CODEC_ID_NONE) fail("unsupported video codec: FFmpeg does not know the stream's codec");
      fail(fmt::format("unsupported video codec '{}' (no decoder for it in this FFmpeg build)", avcodec_get_name(id)));
    }
    if (best < 0) fail(fmt::format("cannot select a video stream: {}", error_string(best)));
    stream = format->streams[best];
    info.stream_index = best;
    const AVCodecParameters& par = *stream->codecpar;
    info.video_codec = avcodec_get_name(par.codec_id);

    // No size at all: neither the container nor a decoded frame told it, e.g. a PNG whose header
    // claims more than the pixel limit (probing did not decode it).
    if (par.width == 0 && par.height == 0)
      fail(
          fmt::format("cannot tell the frame size: the first frame does not decode (damaged, or more than the "
                      "limit of {} pixels: --max-pixels raises it)",
                      options.max_pixels));
    if (par.width <= 0 || par.height <= 0 || par.width > kMaxVideoDimension || par.height > kMaxVideoDimension)
      fail(fmt::format("absurd frame size {}x{} (must be 1 to {} pixels each way)", par.width, par.height,
                       kMaxVideoDimension));
    check_pixel_limit(par.width, par.height, "");
    info.coded_width = par.width;
    info.coded_height = par.height;
    const AVRational sar = av_guess_sample_aspect_ratio(format.get(), stream, nullptr);
    if (sar.num > 0 && sar.den > 0) {
      info.sar_num = sar.num;
      info.sar_den = sar.den;
    }
    info.rotation_degrees = options.apply_rotation ? rotation_from_display_matrix(*stream) : 0;
    const bool quarter_turn = info.rotation_degrees == 90 || info.rotation_degrees == 270;
    info.width = quarter_turn ? par.height : par.width;
    info.height = quarter_turn ? par.width : par.height;
    const double coded_aspect = static_cast<double>(par.width) * info.sar_num / info.sar_den / par.height;
    info.display_aspect = quarter_turn ? 1.0 / coded_aspect : coded_aspect;

    info.fps = rational_or_zero(stream->avg_frame_rate);
    if (info.fps == 0.0) info.fps = rational_or_zero(stream->r_frame_rate);
    if (stream->duration != AV_NOPTS_VALUE && stream->duration > 0)
      info.duration_s = static_cast<double>(stream->duration) * av_q2d(stream->time_base);
    else if (format->duration != AV_NOPTS_VALUE && format->duration > 0)
      info.duration_s = static_cast<double>(format->duration) / AV_TIME_BASE;
    if (stream->start_time != AV_NOPTS_VALUE)
      info.start_time_s = static_cast<double>(stream->start_time) * av_q2d(stream->time_base);
    if (stream->nb_frames > 0) info.frame_count = stream->nb_frames;
    // A pipe cannot go back; image2 and other demuxers without their own I/O seek by reopening.
    info.seekable = !info.live && (!format->pb || (format->pb->seekable & AVIO_SEEKABLE_NORMAL) != 0);

    const auto pixel_format = static_cast<AVPixelFormat>(par.format);
    if (const char* name = av_get_pix_fmt_name(pixel_format)) info.pixel_format = name;
    info.bits_per_component = bits_of(pixel_format);
    info.matrix = matrix_from_av(raw_value(par.color_space), info.matrix_tagged);
    if (!info.matrix_tagged) info.matrix = default_matrix_for_height(par.height);
    if (!is_yuv_or_gray(pixel_format) && pixel_format != AV_PIX_FMT_NONE) {
      info.matrix = ColorMatrix::rgb;
      info.matrix_tagged = true;
    }
    info.range = is_full_range(pixel_format, raw_value(par.color_range)) ? ColorRange::full : ColorRange::limited;
    info.stream_stereo = stereo_metadata_from_stream(*stream);

    codec.reset(avcodec_alloc_context3(decoder));
    if (!codec) fail("out of memory allocating the decoder");
    if (const int copied = avcodec_parameters_to_context(codec.get(), &par); copied < 0)
      fail(fmt::format("cannot set up the {} decoder: {}", info.video_codec, error_string(copied)));
    codec->pkt_timebase = stream->time_base;
    codec->max_pixels = options.max_pixels;  // a larger frame later in the stream is not decoded either
    codec->thread_count = 0;                 // one per core
    codec->thread_type = FF_THREAD_FRAME | FF_THREAD_SLICE;
    if (const int codec_opened = avcodec_open2(codec.get(), decoder, nullptr); codec_opened < 0)
      fail(fmt::format("cannot open the {} decoder: {}", info.video_codec, error_string(codec_opened)));

    packet.reset(av_packet_alloc());
    frame.reset(av_frame_alloc());
    converted.reset(av_frame_alloc());
    last.reset(av_frame_alloc());
    if (!packet || !frame || !converted || !last) fail("out of memory");
  }

  // Frames the container promised but that never arrived (a truncated file). With an index
  // (nb_frames) the count is exact. Without one, the container's duration is compared with how far
  // the packets read reached (any stream: audio often runs past the video), and the time missing is
  // counted in the stream's own mean frame interval. A frame count from duration × nominal rate
  // would call every variable-frame-rate file damaged; a shortfall of one frame is rounding.
  void count_missing_frames() {
    if (seeked) return;  // the container's promise counts from the start, which was skipped
    if (info.frame_count) {
      stats.missing_frames = std::max<std::int64_t>(0, *info.frame_count - stats.frames_decoded);
      return;
    }
    // A duration guessed from the bit rate promises nothing.
    if (format->duration == AV_NOPTS_VALUE || format->duration <= 0 ||
        format->duration_estimation_method == AVFMT_DURATION_FROM_BITRATE || !packets_end_s)
      return;
    const double start = format->start_time != AV_NOPTS_VALUE ? static_cast<double>(format->start_time) : 0.0;
    const double promised_end = (start + static_cast<double>(format->duration)) / AV_TIME_BASE;
    double interval = info.fps > 0.0 ? 1.0 / info.fps : 0.0;
    if (stats.frames_decoded >= 2 && first_frame_s && last_frame_s && *last_frame_s > *first_frame_s)
      interval = (*last_frame_s - *first_frame_s) / static_cast<double>(stats.frames_decoded - 1);
    if (interval <= 0.0) return;
    const auto shortfall = static_cast<std::int64_t>(std::llround((promised_end - *packets_end_s) / interval));
    stats.missing_frames = shortfall > 1 ? shortfall : 0;
  }

  void colour_of(const AVFrame& decoded, AVPixelFormat& source_format, int& colorspace, bool& full_range) const {
    const auto decoded_format = static_cast<AVPixelFormat>(decoded.format);
    // The frame's own tag (H.264 VUI) wins; an untagged frame inherits the container's.
    const int frame_range = raw_value(decoded.color_range);
    const int range = frame_range != AVCOL_RANGE_UNSPECIFIED ? frame_range : raw_value(stream->codecpar->color_range);
    full_range = is_full_range(decoded_format, range);
    bool jpeg = false;
    source_format = without_jpeg_range(decoded_format, jpeg);
    bool tagged = false;
    ColorMatrix matrix = matrix_from_av(raw_value(decoded.colorspace), tagged);
    if (!tagged) matrix = info.matrix_tagged ? info.matrix : default_matrix_for_height(decoded.height);
    colorspace = sws_colorspace_for(matrix);
  }

  void prepare_converter(const AVFrame& decoded, AVPixelFormat& source_format, int& colorspace, bool& full_range) {
    colour_of(decoded, source_format, colorspace, full_range);
    if (sws && sws_width == decoded.width && sws_height == decoded.height && sws_format == source_format &&
        sws_colorspace == colorspace && sws_full_range == static_cast<int>(full_range))
      return;
    const AVPixelFormat target = bits_of(source_format) > 8 ? AV_PIX_FMT_RGBA64 : AV_PIX_FMT_RGBA;
    // Full chroma interpolation and accurate rounding: no scaling happens, so quality is cheap.
    sws.reset(sws_getContext(decoded.width, decoded.height, source_format, decoded.width, decoded.height, target,
                             SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT | SWS_FULL_CHR_H_INP, nullptr, nullptr,
                             nullptr));
    if (!sws)
      fail(fmt::format("cannot convert pixel format {} to RGBA",
                       av_get_pix_fmt_name(source_format) ? av_get_pix_fmt_name(source_format) : "unknown"));
    const int* coefficients = sws_getCoefficients(colorspace);
    // Output RGB is always full range; brightness 0, contrast and saturation 1.0 (16.16 fixed point).
    sws_setColorspaceDetails(sws.get(), coefficients, full_range ? 1 : 0, coefficients, 1, 0, 1 << 16, 1 << 16);
    sws_width = decoded.width;
    sws_height = decoded.height;
    sws_format = source_format;
    sws_colorspace = colorspace;
    sws_full_range = full_range ? 1 : 0;

    av_frame_unref(converted.get());
    converted->format = target;
    converted->width = decoded.width;
    converted->height = decoded.height;
    if (const int allocated = av_frame_get_buffer(converted.get(), 0); allocated < 0)
      fail(fmt::format("cannot allocate a {}x{} frame: {}", decoded.width, decoded.height, error_string(allocated)));
  }

  // Whether `regions` can be cut from frames like `decoded` and area-averaged by swscale.
  bool can_reduce(const AVFrame& decoded, const std::vector<ReducedRegion>& wanted) const {
    if (info.rotation_degrees != 0 || wanted.empty()) return false;
    const AVPixFmtDescriptor* desc = av_pix_fmt_desc_get(static_cast<AVPixelFormat>(decoded.format));
    if (desc == nullptr || (desc->flags & (AV_PIX_FMT_FLAG_BITSTREAM | AV_PIX_FMT_FLAG_PAL | AV_PIX_FMT_FLAG_HWACCEL)))
      return false;
    for (const ReducedRegion& r : wanted) {
      if (r.block_x < 1 || r.block_y < 1 || r.width <= 0 || r.height <= 0 || r.width % r.block_x != 0 ||
          r.height % r.block_y != 0 || r.x < 0 || r.y < 0 || r.x + r.width > decoded.width ||
          r.y + r.height > decoded.height)
        return false;
      if (r.width != wanted[0].width || r.height != wanted[0].height || r.block_x != wanted[0].block_x ||
          r.block_y != wanted[0].block_y)
        return false;
      // Cropping moves the chroma planes by whole samples only.
      if (r.x % (1 << desc->log2_chroma_w) != 0 || r.y % (1 << desc->log2_chroma_h) != 0) return false;
    }
    return true;
  }

  // Each region of `decoded`, cropped (pointers only) and area-averaged to RGBA in one swscale call.
  void convert_regions(AVFrame& decoded, VideoFrame& out) {
    AVPixelFormat source_format = AV_PIX_FMT_NONE;
    int colorspace = 0;
    bool full_range = false;
    colour_of(decoded, source_format, colorspace, full_range);
    const ReducedRegion& size = regions.front();
    const int out_w = size.width / size.block_x, out_h = size.height / size.block_y;
    const AVPixelFormat target = bits_of(source_format) > 8 ? AV_PIX_FMT_RGBA64 : AV_PIX_FMT_RGBA;
    // Each region's block means from its planes (`planes_of`), straight to 8-bit RGBA.
    const auto means_of_regions = [&](const auto& planes_of) {
      const YuvToRgb matrix = yuv_to_rgb_from_sws(sws_getCoefficients(colorspace), full_range);
      for (const ReducedRegion& r : regions) {
        if (r.x + r.width > decoded.width || r.y + r.height > decoded.height)
          fail(fmt::format("the frame size changed mid-stream ({}x{})", decoded.width, decoded.height));
        std::vector<std::uint8_t> pixels(static_cast<std::size_t>(out_w) * static_cast<std::size_t>(out_h) * 4);
        yuv420_block_means(planes_of(r), r.width, r.height, r.block_x, r.block_y, matrix, pixels.data(),
                           static_cast<std::size_t>(out_w) * 4);
        out.reduced.push_back(std::move(pixels));
      }
      out.bits = 8;
    };
    if (source_format == AV_PIX_FMT_YUV420P && yuv420_block_means_supported(size.block_x, size.block_y)) {
      // Most video: block means of 8-bit 4:2:0 without swscale (inputs/yuv_block_means.hpp).
      means_of_regions([&](const ReducedRegion& r) {
        return Yuv420Planes{.y = decoded.data[0] + static_cast<std::ptrdiff_t>(r.y) * decoded.linesize[0] + r.x,
                            .u = decoded.data[1] + static_cast<std::ptrdiff_t>(r.y / 2) * decoded.linesize[1] + r.x / 2,
                            .v = decoded.data[2] + static_cast<std::ptrdiff_t>(r.y / 2) * decoded.linesize[2] + r.x / 2,
                            .y_stride = decoded.linesize[0],
                            .u_stride = decoded.linesize[1],
                            .v_stride = decoded.linesize[2]};
      });
      return;
    }
    const AVPixFmtDescriptor* desc = av_pix_fmt_desc_get(source_format);
    if (reduce_max_bits <= 8 && desc && desc->nb_components == 3 && desc->log2_chroma_w == 1 &&
        desc->log2_chroma_h == 1 && (desc->flags & (AV_PIX_FMT_FLAG_BE | AV_PIX_FMT_FLAG_RGB)) == 0 &&
        desc->comp[0].depth > 8 && desc->comp[0].step == 2 && desc->comp[0].shift == 0 &&
        yuv420_block_means_supported(size.block_x, size.block_y)) {
      // 10-bit (or deeper) 4:2:0 for an 8-bit output: the same block means, dithered to 8 bits,
      // so that the CPU composite tables take them (play keeps pace with a 10-bit movie).
      const auto plane = [&](int i, int x, int y) {
        return reinterpret_cast<const std::uint16_t*>(decoded.data[i] +
                                                      static_cast<std::ptrdiff_t>(y) * decoded.linesize[i]) +
               x;
      };
      means_of_regions([&](const ReducedRegion& r) {
        return Yuv420Planes16{.y = plane(0, r.x, r.y),
                              .u = plane(1, r.x / 2, r.y / 2),
                              .v = plane(2, r.x / 2, r.y / 2),
                              .y_stride = decoded.linesize[0] / 2,
                              .u_stride = decoded.linesize[1] / 2,
                              .v_stride = decoded.linesize[2] / 2,
                              .bits = desc->comp[0].depth};
      });
      return;
    }
    if (!reduce_sws || reduce_format != source_format || reduce_colorspace != colorspace ||
        reduce_full_range != static_cast<int>(full_range)) {
      // SWS_AREA at a whole-number ratio weighs the pixels of each block equally (the prefilter's
      // block mean); full chroma resolution in and out, accurate rounding.
      reduce_sws.reset(sws_getContext(size.width, size.height, source_format, out_w, out_h, target,
                                      SWS_AREA | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT | SWS_FULL_CHR_H_INP, nullptr,
                                      nullptr, nullptr));
      if (!reduce_sws)
        fail(fmt::format("cannot convert pixel format {} to RGBA",
                         av_get_pix_fmt_name(source_format) ? av_get_pix_fmt_name(source_format) : "unknown"));
      const int* coefficients = sws_getCoefficients(colorspace);
      sws_setColorspaceDetails(reduce_sws.get(), coefficients, full_range ? 1 : 0, coefficients, 1, 0, 1 << 16,
                               1 << 16);
      reduce_format = source_format;
      reduce_colorspace = colorspace;
      reduce_full_range = full_range ? 1 : 0;
    }
    const int bytes_per_pixel = target == AV_PIX_FMT_RGBA64 ? 8 : 4;
    out.bits = bytes_per_pixel == 8 ? 16 : 8;
    FramePtr crop(av_frame_alloc());
    if (!crop) fail("out of memory");
    for (const ReducedRegion& r : regions) {
      if (r.x + r.width > decoded.width || r.y + r.height > decoded.height)
        fail(fmt::format("the frame size changed mid-stream ({}x{})", decoded.width, decoded.height));
      av_frame_unref(crop.get());
      if (const int referenced = av_frame_ref(crop.get(), &decoded); referenced < 0)
        fail(fmt::format("cannot reference a decoded frame: {}", error_string(referenced)));
      crop->crop_left = static_cast<std::size_t>(r.x);
      crop->crop_top = static_cast<std::size_t>(r.y);
      crop->crop_right = static_cast<std::size_t>(decoded.width - r.x - r.width);
      crop->crop_bottom = static_cast<std::size_t>(decoded.height - r.y - r.height);
      if (const int cropped = av_frame_apply_cropping(crop.get(), AV_FRAME_CROP_UNALIGNED); cropped < 0)
        fail(fmt::format("cannot cut a view out of a frame: {}", error_string(cropped)));
      std::vector<std::uint8_t> pixels(static_cast<std::size_t>(out_w) * static_cast<std::size_t>(out_h) *
                                       static_cast<std::size_t>(bytes_per_pixel));
      std::uint8_t* planes[4] = {pixels.data(), nullptr, nullptr, nullptr};
      const int strides[4] = {out_w * bytes_per_pixel, 0, 0, 0};
      if (const int rows = sws_scale(reduce_sws.get(), crop->data, crop->linesize, 0, r.height, planes, strides);
          rows != out_h)
        fail(fmt::format("cannot convert a {}x{} view to RGBA: {}", r.width, r.height,
                         rows < 0 ? error_string(rows) : std::string("incomplete output")));
      out.reduced.push_back(std::move(pixels));
    }
  }

  VideoFrame convert(AVFrame& decoded) {
    if (decoded.width <= 0 || decoded.height <= 0 || decoded.width > kMaxVideoDimension ||
        decoded.height > kMaxVideoDimension)
      fail(fmt::format("absurd frame size {}x{} in the stream", decoded.width, decoded.height));
    check_pixel_limit(decoded.width, decoded.height, " later in the stream");
    VideoFrame out;
    if (!regions.empty()) {
      convert_regions(decoded, out);
      out.width = decoded.width;
      out.height = decoded.height;
    } else {
      convert_whole(decoded, out);
    }
    finish_frame(decoded, out);
    return out;
  }

  void convert_whole(AVFrame& decoded, VideoFrame& out) {
    AVPixelFormat source_format = AV_PIX_FMT_NONE;
    int colorspace = 0;
    bool full_range = false;
    prepare_converter(decoded, source_format, colorspace, full_range);
    if (const int writable = av_frame_make_writable(converted.get()); writable < 0)
      fail(fmt::format("cannot write a converted frame: {}", error_string(writable)));
    if (const int rows = sws_scale(sws.get(), decoded.data, decoded.linesize, 0, decoded.height, converted->data,
                                   converted->linesize);
        rows != decoded.height)
      fail(fmt::format("cannot convert a {}x{} frame to RGBA: {}", decoded.width, decoded.height,
                       rows < 0 ? error_string(rows) : std::string("incomplete output")));

    const int rotation = info.rotation_degrees;
    const bool quarter_turn = rotation == 90 || rotation == 270;
    out.width = quarter_turn ? decoded.height : decoded.width;
    out.height = quarter_turn ? decoded.width : decoded.height;
    out.bits = converted->format == AV_PIX_FMT_RGBA64 ? 16 : 8;
    if (out.bits == 16)
      copy_rotated(converted->data[0], converted->linesize[0], decoded.width, decoded.height, rotation, out.rgba16);
    else
      copy_rotated(converted->data[0], converted->linesize[0], decoded.width, decoded.height, rotation, out.rgba8);
  }

  // Aspect, timestamp and side data of a converted frame.
  void finish_frame(AVFrame& decoded, VideoFrame& out) {
    const int rotation = info.rotation_degrees;
    const bool quarter_turn = rotation == 90 || rotation == 270;
    AVRational sar = av_guess_sample_aspect_ratio(format.get(), stream, &decoded);
    if (sar.num <= 0 || sar.den <= 0) sar = AVRational{1, 1};
    const double coded_aspect = static_cast<double>(decoded.width) * av_q2d(sar) / decoded.height;
    out.display_aspect = quarter_turn ? 1.0 / coded_aspect : coded_aspect;

    if (decoded.best_effort_timestamp != AV_NOPTS_VALUE)
      out.pts_s = static_cast<double>(decoded.best_effort_timestamp) * av_q2d(stream->time_base);
    else  // no timestamp at all: continue at the nominal rate
      out.pts_s = frames_out == 0 ? info.start_time_s : last_pts_s + (info.fps > 0.0 ? 1.0 / info.fps : 0.0);
    last_pts_s_before = last_pts_s;
    last_pts_s = out.pts_s;
    out.key_frame = decoded.key_frame != 0;
    out.stereo = stereo_metadata_from_frame(decoded);
    if (out.stereo) frame_stereo = out.stereo;
    ++frames_out;
  }

  std::optional<VideoFrame> next_frame() {
    if (finished) return std::nullopt;
    for (;;) {
      // Not every device checks FFmpeg's interrupt callback while it waits (x11grab sleeps to its
      // next frame): an interrupted one ends at its next frame at the latest.
      if (network.interrupted) {
        finished = true;
        return std::nullopt;
      }
      const int received = avcodec_receive_frame(codec.get(), frame.get());
      if (received == 0) {
        consecutive_errors = 0;
        ++stats.frames_decoded;
        if ((frame->flags & AV_FRAME_FLAG_CORRUPT) != 0 || frame->decode_error_flags != 0) ++stats.decode_errors;
        if (frame->best_effort_timestamp != AV_NOPTS_VALUE) {
          const double t = static_cast<double>(frame->best_effort_timestamp) * av_q2d(stream->time_base);
          first_frame_s = std::min(first_frame_s.value_or(t), t);
          last_frame_s = std::max(last_frame_s.value_or(t), t);
        }
        VideoFrame out = convert(*frame);
        av_frame_unref(last.get());
        av_frame_move_ref(last.get(), frame.get());
        return out;
      }
      if (received == AVERROR_EOF) {
        finished = true;
        count_missing_frames();
        return std::nullopt;
      }
      if (received != AVERROR(EAGAIN)) {
        ++stats.decode_errors;
        // A decoder that fails on every call would otherwise spin forever on a hostile file.
        if (++consecutive_errors > 1000) fail(fmt::format("the decoder keeps failing: {}", error_string(received)));
        continue;
      }
      if (draining) {  // nothing more can come out
        finished = true;
        count_missing_frames();
        return std::nullopt;
      }
      const int read = av_read_frame(format.get(), packet.get());
      if (read < 0) {
        if (read != AVERROR_EOF && !network.interrupted) ++stats.read_errors;  // interrupted: ended, not lost
        draining = true;
        avcodec_send_packet(codec.get(), nullptr);
        continue;
      }
      if (const std::int64_t ts = packet->pts != AV_NOPTS_VALUE ? packet->pts : packet->dts; ts != AV_NOPTS_VALUE) {
        const double end = static_cast<double>(ts + std::max<std::int64_t>(packet->duration, 0)) *
                           av_q2d(format->streams[packet->stream_index]->time_base);
        packets_end_s = std::max(packets_end_s.value_or(end), end);
      }
      // The second view's NAL units come with the base view's from the first access unit on.
      if (info.multiview == Multiview::none && multiview_packets_left > 0) {
        --multiview_packets_left;
        const AVCodecParameters& packet_codec = *format->streams[packet->stream_index]->codecpar;
        if (packet_codec.codec_type == AVMEDIA_TYPE_VIDEO)
          info.multiview = multiview_from_packet(
              packet_codec, {packet->data, packet->data ? static_cast<std::size_t>(packet->size) : 0u});
      }
      if (packet->stream_index == info.stream_index) {
        // The demuxer's parser reads each packet's header (H.264/HEVC/MPEG-2 sequence headers):
        // a stream that switches to frames over the limit is refused here, with their size,
        // rather than by the decoder (which would only count errors).
        if (const AVCodecParserContext* parser = av_stream_get_parser(stream);
            parser != nullptr && parser->width > 0 && parser->height > 0)
          check_pixel_limit(parser->width, parser->height, " later in the stream");
        if ((packet->flags & AV_PKT_FLAG_CORRUPT) != 0) ++stats.decode_errors;
        const int sent = avcodec_send_packet(codec.get(), packet.get());
        if (sent < 0 && sent != AVERROR(EAGAIN)) {
          ++stats.decode_errors;
          if (++consecutive_errors > 1000) fail(fmt::format("the decoder keeps failing: {}", error_string(sent)));
        }
      }
      av_packet_unref(packet.get());
    }
  }
};

VideoSource::VideoSource(const std::string& path, VideoSourceOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->open(path);
}

VideoSource::~VideoSource() = default;
VideoSource::VideoSource(VideoSource&&) noexcept = default;
VideoSource& VideoSource::operator=(VideoSource&&) noexcept = default;

const VideoInfo& VideoSource::info() const { return impl_->info; }
std::optional<VideoFrame> VideoSource::next_frame() {
  for (;;) {
    auto frame = impl_->next_frame();
    if (!frame || !impl_->pending_after_seek || frame->pts_s >= *impl_->pending_after_seek) {
      impl_->pending_after_seek.reset();
      return frame;
    }
  }
}
const DecodeStats& VideoSource::stats() const { return impl_->stats; }

bool VideoSource::reduce_regions(std::vector<ReducedRegion> regions, int max_bits) {
  Impl& m = *impl_;
  if (!regions.empty()) {
    if (m.last->buf[0] == nullptr) return false;  // nothing decoded yet to check the format against
    if (!m.can_reduce(*m.last, regions)) return false;
  }
  m.regions = std::move(regions);
  m.reduce_max_bits = max_bits;
  return true;
}

std::optional<VideoFrame> VideoSource::convert_last() {
  Impl& m = *impl_;
  if (m.last->buf[0] == nullptr) return std::nullopt;
  --m.frames_out;  // the same frame again: keep the timestamp continuation as it was
  m.last_pts_s = m.last_pts_s_before;
  return m.convert(*m.last);
}

void VideoSource::seek(double seconds) {
  Impl& m = *impl_;
  // 0 is a real seek too: a player going back to the start after playing.
  seconds = std::max(seconds, 0.0);
  const double target = m.info.start_time_s + seconds;
  const auto timestamp = static_cast<std::int64_t>(std::floor(target / av_q2d(m.stream->time_base)));
  if (av_seek_frame(m.format.get(), m.stream->index, timestamp, AVSEEK_FLAG_BACKWARD) < 0)
    m.fail(fmt::format("cannot seek to {:.3f} s", seconds));
  avcodec_flush_buffers(m.codec.get());
  m.draining = false;
  m.finished = false;
  m.consecutive_errors = 0;
  m.seeked = true;
  // Decode from the keyframe up to the target; the caller gets the first frame at or after it.
  m.pending_after_seek = target - 0.5 * (m.info.fps > 0 ? 1.0 / m.info.fps : 0.0);
}

std::optional<StereoMetadata> VideoSource::stereo_metadata() const {
  return impl_->info.stream_stereo ? impl_->info.stream_stereo : impl_->frame_stereo;
}
std::optional<StereoMetadata> VideoSource::frame_stereo_metadata() const { return impl_->frame_stereo; }

void VideoSource::interrupt() { impl_->network.interrupted = true; }

void quiet_ffmpeg_logs(bool quiet) { av_log_set_level(quiet ? AV_LOG_QUIET : AV_LOG_INFO); }

}  // namespace nelf
