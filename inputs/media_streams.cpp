#include "inputs/media_streams.hpp"

#include <fmt/format.h>

extern "C" {
#include <libavutil/channel_layout.h>
#include <libavutil/pixdesc.h>
}

#include "core/ffmpeg_raii.hpp"
#include "inputs/ffmpeg_input.hpp"
#include "inputs/video_source.hpp"

namespace nelf {
namespace {

// Packets looked at for a second view: its NAL units come with every access unit.
constexpr int kMultiviewPackets = 64;

std::string tag(const AVDictionary* metadata, const char* key) {
  const AVDictionaryEntry* entry = av_dict_get(metadata, key, nullptr, 0);
  return entry && entry->value ? entry->value : "";
}

std::string type_name(AVMediaType type) {
  const char* name = av_get_media_type_string(type);
  return name ? name : "unknown";
}

MediaStream describe(const AVStream& stream) {
  const AVCodecParameters& par = *stream.codecpar;
  MediaStream out;
  out.index = stream.index;
  out.type = type_name(par.codec_type);
  const AVCodecDescriptor* descriptor = avcodec_descriptor_get(par.codec_id);
  out.codec = descriptor ? descriptor->name : "unknown";
  if (const char* profile = avcodec_profile_name(par.codec_id, par.profile)) out.profile = profile;
  out.language = tag(stream.metadata, "language");
  out.title = tag(stream.metadata, "title");
  out.is_default = (stream.disposition & AV_DISPOSITION_DEFAULT) != 0;
  out.forced = (stream.disposition & AV_DISPOSITION_FORCED) != 0;
  out.hearing_impaired = (stream.disposition & AV_DISPOSITION_HEARING_IMPAIRED) != 0;
  out.visual_impaired = (stream.disposition & AV_DISPOSITION_VISUAL_IMPAIRED) != 0;
  out.cover_art = (stream.disposition & AV_DISPOSITION_ATTACHED_PIC) != 0;
  if (par.codec_type == AVMEDIA_TYPE_VIDEO) {
    out.width = par.width;
    out.height = par.height;
    const AVRational rate = stream.avg_frame_rate.num > 0 ? stream.avg_frame_rate : stream.r_frame_rate;
    if (rate.num > 0 && rate.den > 0) out.fps = av_q2d(rate);
    if (const char* name = av_get_pix_fmt_name(static_cast<AVPixelFormat>(par.format))) out.pixel_format = name;
    out.stereo = stereo_metadata_from_stream(stream);
    out.multiview = multiview_from_codec(par);
  } else if (par.codec_type == AVMEDIA_TYPE_AUDIO) {
    out.channels = par.ch_layout.nb_channels;
    out.sample_rate = par.sample_rate;
    char layout[128] = {};
    if (av_channel_layout_describe(&par.ch_layout, layout, sizeof layout) > 0) out.channel_layout = layout;
  } else if (par.codec_type == AVMEDIA_TYPE_ATTACHMENT) {
    out.filename = tag(stream.metadata, "filename");
    out.mimetype = tag(stream.metadata, "mimetype");
  }
  return out;
}

}  // namespace

MediaStreams describe_media_streams(const std::string& path, bool allow_network) {
  ffmpeg::InputGuard guard;
  guard.allow_network = allow_network;
  ffmpeg::FormatContextPtr format;
  const int opened = ffmpeg::open_input(format, path, guard);
  if (const auto stopped = ffmpeg::guard_stop(path, guard)) throw VideoError(*stopped);
  if (opened < 0) throw VideoError(fmt::format("{}: cannot open: {}", path, ffmpeg::error_string(opened)));
  const int found = ffmpeg::find_stream_info(format.get(), guard);
  if (const auto stopped = ffmpeg::guard_stop(path, guard)) throw VideoError(*stopped);
  if (found < 0) throw VideoError(fmt::format("{}: cannot read stream information", path));

  MediaStreams out;
  for (unsigned i = 0; i < format->nb_streams; ++i) out.streams.push_back(describe(*format->streams[i]));
  ffmpeg::PacketPtr packet(av_packet_alloc());
  if (!packet) throw std::bad_alloc();
  for (int read = 0; read < kMultiviewPackets && av_read_frame(format.get(), packet.get()) >= 0; ++read) {
    MediaStream& stream = out.streams[static_cast<std::size_t>(packet->stream_index)];
    if (stream.multiview == Multiview::none && stream.type == "video")
      stream.multiview = multiview_from_packet(*format->streams[packet->stream_index]->codecpar,
                                               {packet->data, static_cast<std::size_t>(packet->size)});
    av_packet_unref(packet.get());
  }
  for (unsigned i = 0; i < format->nb_chapters; ++i) {
    const AVChapter& chapter = *format->chapters[i];
    out.chapters.push_back({chapter.id, static_cast<double>(chapter.start) * av_q2d(chapter.time_base),
                            static_cast<double>(chapter.end) * av_q2d(chapter.time_base),
                            tag(chapter.metadata, "title")});
  }
  return out;
}

}  // namespace nelf
