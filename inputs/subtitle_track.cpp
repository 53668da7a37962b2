#include "inputs/subtitle_track.hpp"

#include <ass/ass.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <vector>

#include "core/ffmpeg_raii.hpp"
#include "core/language_tags.hpp"
#include "core/printable.hpp"
#include "core/user_error.hpp"

namespace nelf {
namespace {

struct AssLibraryDeleter {
  void operator()(ASS_Library* library) const { ass_library_done(library); }
};
struct AssRendererDeleter {
  void operator()(ASS_Renderer* renderer) const { ass_renderer_done(renderer); }
};
struct AssTrackDeleter {
  void operator()(ASS_Track* track) const { ass_free_track(track); }
};
struct SubtitleDeleter {
  void operator()(AVSubtitle* subtitle) const {
    avsubtitle_free(subtitle);
    delete subtitle;
  }
};

std::string av_error(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

// "over" of a premultiplied source colour with coverage `a` (0..255) onto premultiplied `dst`.
void blend_premultiplied(std::uint8_t* dst, int r, int g, int b, int a) {
  const int keep = 255 - a;
  dst[0] = static_cast<std::uint8_t>((r * a + dst[0] * keep + 127) / 255);
  dst[1] = static_cast<std::uint8_t>((g * a + dst[1] * keep + 127) / 255);
  dst[2] = static_cast<std::uint8_t>((b * a + dst[2] * keep + 127) / 255);
  dst[3] = static_cast<std::uint8_t>((255 * a + dst[3] * keep + 127) / 255);
}

// One picture of a bitmap track: premultiplied RGBA at its place on the subtitle canvas.
struct BitmapRect {
  int x = 0, y = 0, w = 0, h = 0;
  std::vector<std::uint8_t> rgba;
};

// A bitmap subtitle from `start_s` until `end_s`, authored on a `canvas_w`×`canvas_h` canvas.
struct BitmapEvent {
  double start_s = 0.0, end_s = 0.0;
  int canvas_w = 0, canvas_h = 0;
  std::vector<BitmapRect> rects;
};

// A rect of palette indices (AV_PIX_FMT_PAL8: the palette is native-endian ARGB, not
// premultiplied) as premultiplied RGBA.
BitmapRect premultiplied(const AVSubtitleRect& rect) {
  BitmapRect out{rect.x, rect.y, rect.w, rect.h, {}};
  out.rgba.resize(static_cast<std::size_t>(rect.w) * rect.h * 4);
  std::uint32_t palette[256] = {};
  std::memcpy(palette, rect.data[1], static_cast<std::size_t>(std::clamp(rect.nb_colors, 0, 256)) * 4);
  for (int y = 0; y < rect.h; ++y)
    for (int x = 0; x < rect.w; ++x) {
      const std::uint32_t argb = palette[rect.data[0][static_cast<std::size_t>(y) * rect.linesize[0] + x]];
      const unsigned a = argb >> 24;
      std::uint8_t* d = &out.rgba[(static_cast<std::size_t>(y) * rect.w + x) * 4];
      d[0] = static_cast<std::uint8_t>((((argb >> 16) & 0xff) * a + 127) / 255);
      d[1] = static_cast<std::uint8_t>((((argb >> 8) & 0xff) * a + 127) / 255);
      d[2] = static_cast<std::uint8_t>(((argb & 0xff) * a + 127) / 255);
      d[3] = static_cast<std::uint8_t>(a);
    }
  return out;
}

// The premultiplied colour of `rect` at canvas point (`cx`, `cy`) (pixel centres at .5), bilinear
// between its pixels and transparent outside it: `rgba` gets the four channels.
void sample(const BitmapRect& rect, double cx, double cy, int rgba[4]) {
  const double fx = cx - rect.x - 0.5, fy = cy - rect.y - 0.5;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  const double tx = fx - x0, ty = fy - y0;
  double sum[4] = {};
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int x = x0 + i, y = y0 + j;
      if (x < 0 || y < 0 || x >= rect.w || y >= rect.h) continue;
      const double weight = (i ? tx : 1.0 - tx) * (j ? ty : 1.0 - ty);
      const std::uint8_t* p = &rect.rgba[(static_cast<std::size_t>(y) * rect.w + x) * 4];
      for (int c = 0; c < 4; ++c) sum[c] += weight * p[c];
    }
  for (int c = 0; c < 4; ++c) rgba[c] = static_cast<int>(std::lround(sum[c]));
}

// Opens `path` as FFmpeg reads a subtitle file or a movie for its subtitles: files and pipes only
// (a local playlist naming http:// entries is not fetched; the movie's own source asks for
// --allow-network, subtitles are only looked for in local files).
int open_local(AVFormatContext** format, const std::string& path) {
  AVDictionary* options = nullptr;
  av_dict_set(&options, "protocol_whitelist", "file,pipe", 0);
  const int opened = avformat_open_input(format, path.c_str(), nullptr, &options);
  av_dict_free(&options);
  return opened;
}

// The demuxer skips the packets of every stream but `index`.
void read_only_stream(AVFormatContext& format, int index) {
  for (unsigned i = 0; i < format.nb_streams; ++i)
    if (static_cast<int>(i) != index) format.streams[i]->discard = AVDISCARD_ALL;
}

std::string stream_language(const AVFormatContext& format, unsigned i) {
  const AVDictionaryEntry* tag = av_dict_get(format.streams[i]->metadata, "language", nullptr, 0);
  return tag ? tag->value : "";
}

// "eng, subrip": how a track list names a subtitle stream.
std::string stream_words(const AVFormatContext& format, unsigned i) {
  const std::string language = stream_language(format, i);
  return fmt::format("{}, {}", language.empty() ? "no language" : language,
                     avcodec_get_name(format.streams[i]->codecpar->codec_id));
}

}  // namespace

struct SubtitleTrack::Impl {
  std::string path;
  double offset_s = 0.0;
  SubtitleStreamChoice choice;
  std::string description;
  ffmpeg::FormatContextPtr format;
  ffmpeg::CodecContextPtr codec;
  ffmpeg::PacketPtr packet{av_packet_alloc()};
  AVStream* stream = nullptr;
  bool at_end = false;
  double read_until_s = -std::numeric_limits<double>::infinity();  // packets read up to here
  double last_asked_s = -std::numeric_limits<double>::infinity();
  // Text: libass.
  std::unique_ptr<ASS_Library, AssLibraryDeleter> library;
  std::unique_ptr<ASS_Renderer, AssRendererDeleter> renderer;
  std::unique_ptr<ASS_Track, AssTrackDeleter> track;
  int frame_w = 0, frame_h = 0;
  double pixel_aspect = 0.0;
  // Bitmaps: decoded events in start order, and the canvas of those that do not say theirs.
  bool bitmap = false;
  SubtitleStereo stereo = SubtitleStereo::flat;
  std::vector<BitmapEvent> events;
  int video_w = 0, video_h = 0;

  [[noreturn]] void fail(const std::string& why) const {
    throw UserError(fmt::format("{}: {}", printable(path), why), 1);
  }

  void open() {
    AVFormatContext* raw = nullptr;
    if (const int err = open_local(&raw, path); err < 0) fail(fmt::format("cannot open subtitles: {}", av_error(err)));
    format.reset(raw);
    if (const int err = avformat_find_stream_info(format.get(), nullptr); err < 0)
      fail(fmt::format("cannot read subtitles: {}", av_error(err)));
    const int index = chosen_stream();
    stream = format->streams[index];
    // A movie's subtitles share its video's clock, whose first frame is time 0.
    const int video = av_find_best_stream(format.get(), AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
    if (video >= 0 && format->streams[video]->start_time != AV_NOPTS_VALUE)
      offset_s += static_cast<double>(format->streams[video]->start_time) * av_q2d(format->streams[video]->time_base);
    if (video >= 0) {
      video_w = format->streams[video]->codecpar->width;
      video_h = format->streams[video]->codecpar->height;
    }
    read_only_stream(*format, index);
    const AVCodec* decoder = avcodec_find_decoder(stream->codecpar->codec_id);
    if (!decoder) fail(fmt::format("no decoder for subtitles in {}", avcodec_get_name(stream->codecpar->codec_id)));
    codec.reset(avcodec_alloc_context3(decoder));
    if (!codec || avcodec_parameters_to_context(codec.get(), stream->codecpar) < 0) fail("cannot set up the decoder");
    codec->pkt_timebase = stream->time_base;
    if (const int err = avcodec_open2(codec.get(), decoder, nullptr); err < 0)
      fail(fmt::format("cannot open the {} decoder: {}", decoder->name, av_error(err)));
    const AVCodecDescriptor* descriptor = avcodec_descriptor_get(stream->codecpar->codec_id);
    description = fmt::format("subtitles: {} ({})", path, decoder->name);
    if (descriptor && (descriptor->props & AV_CODEC_PROP_BITMAP_SUB) != 0) {
      bitmap = true;
      read_to(first_packet_horizon());
      return;
    }
    if (!descriptor || (descriptor->props & AV_CODEC_PROP_TEXT_SUB) == 0)
      fail(fmt::format("{} subtitles are neither text nor bitmaps that nelf draws", decoder->name));
    library.reset(ass_library_init());
    if (!library) fail("libass cannot start");
    ass_set_message_cb(
        library.get(), [](int, const char*, va_list, void*) {}, nullptr);
    ass_set_extract_fonts(library.get(), 1);
    renderer.reset(ass_renderer_init(library.get()));
    if (!renderer) fail("libass cannot start its renderer");
    ass_set_fonts(renderer.get(), nullptr, "sans-serif", ASS_FONTPROVIDER_AUTODETECT, nullptr, 1);
    track.reset(ass_new_track(library.get()));
    if (!track) fail("libass cannot make a track");
    if (codec->subtitle_header && codec->subtitle_header_size > 0)
      ass_process_codec_private(track.get(), reinterpret_cast<char*>(codec->subtitle_header),
                                codec->subtitle_header_size);
    // A subtitle file that does not parse is refused now, not at its first line: every packet of
    // it is decoded up front (an external file is small; a movie's stream is read as it plays).
    read_to(first_packet_horizon());
  }

  // The stream `choice` names, else FFmpeg's best subtitle stream.
  int chosen_stream() const {
    std::vector<int> streams;
    for (unsigned i = 0; i < format->nb_streams; ++i)
      if (format->streams[i]->codecpar->codec_type == AVMEDIA_TYPE_SUBTITLE) streams.push_back(static_cast<int>(i));
    if (streams.empty()) fail("no subtitle stream");
    const auto language = [&](int i) { return stream_language(*format, static_cast<unsigned>(i)); };
    const auto list = [&] {
      std::string all;
      for (std::size_t n = 0; n < streams.size(); ++n)
        all += fmt::format("{}{}: {}", n ? "; " : "", n + 1, stream_words(*format, static_cast<unsigned>(streams[n])));
      return all;
    };
    if (choice.number) {
      if (*choice.number < 1 || *choice.number > static_cast<int>(streams.size()))
        throw UserError(
            fmt::format("{}: no subtitle track {} (--sid): {}", printable(path), *choice.number, printable(list())), 2);
      return streams[static_cast<std::size_t>(*choice.number - 1)];
    }
    if (!choice.languages.empty()) {
      for (const std::string& wanted : choice.languages)
        for (const int i : streams)
          if (same_language_tag(language(i), wanted)) return i;
      std::string asked;
      for (const std::string& wanted : choice.languages) asked += (asked.empty() ? "" : ",") + wanted;
      throw UserError(fmt::format("{}: no subtitle track in {} (--slang): {}", printable(path), printable(asked),
                                  printable(list())),
                      2);
    }
    return av_find_best_stream(format.get(), AVMEDIA_TYPE_SUBTITLE, -1, -1, nullptr, 0);
  }

  // A movie's stream, and bitmaps (a whole film's pictures would fill memory), are read as they
  // play, seeking back; a text file is read whole.
  bool streamed() const { return format->nb_streams > 1 || bitmap; }
  double first_packet_horizon() const { return streamed() ? 0.0 : std::numeric_limits<double>::infinity(); }

  double seconds(std::int64_t ts) const { return static_cast<double>(ts) * av_q2d(stream->time_base) - offset_s; }

  void decode(AVPacket& p) {
    AVSubtitle sub{};
    int got = 0;
    const int err = avcodec_decode_subtitle2(codec.get(), &sub, &got, &p);
    if (err < 0) fail(fmt::format("subtitles do not decode: {}", av_error(err)));
    if (!got) return;
    const std::unique_ptr<AVSubtitle, SubtitleDeleter> owned(new AVSubtitle(sub));
    const std::int64_t pts = p.pts != AV_NOPTS_VALUE ? p.pts : p.dts;
    if (pts == AV_NOPTS_VALUE) return;
    const double start = seconds(pts) + owned->start_display_time / 1000.0;
    double end = std::numeric_limits<double>::infinity();
    if (p.duration > 0)
      end = seconds(pts + p.duration);
    else if (owned->end_display_time > owned->start_display_time && owned->end_display_time != UINT32_MAX)
      end = seconds(pts) + owned->end_display_time / 1000.0;
    if (bitmap) {
      add_bitmaps(*owned, start, end);
      return;
    }
    const double duration = std::isfinite(end) ? end - start : 3600.0;
    for (unsigned i = 0; i < owned->num_rects; ++i) {
      const AVSubtitleRect& rect = *owned->rects[i];
      if (rect.type != SUBTITLE_ASS || !rect.ass) continue;
      ass_process_chunk(track.get(), rect.ass, static_cast<int>(std::strlen(rect.ass)), std::llround(start * 1000.0),
                        std::llround(duration * 1000.0));
    }
  }

  // The canvas a bitmap is placed on: what the decoder says (PGS's presentation segment, DVB's
  // display definition, VobSub's size line), else DVB's standard 720×576, else the movie's frame.
  std::array<int, 2> bitmap_canvas(const AVSubtitle& sub) const {
    if (codec->width > 0 && codec->height > 0) return {codec->width, codec->height};
    if (codec->codec_id == AV_CODEC_ID_DVB_SUBTITLE) return {720, 576};
    if (video_w > 0 && video_h > 0) return {video_w, video_h};
    int w = 1, h = 1;
    for (unsigned i = 0; i < sub.num_rects; ++i) {
      w = std::max(w, sub.rects[i]->x + sub.rects[i]->w);
      h = std::max(h, sub.rects[i]->y + sub.rects[i]->h);
    }
    return {w, h};
  }

  // A bitmap subtitle replaces the one showing (PGS and DVB compose the whole screen, a DVD shows
  // one subpicture), so it ends any earlier event still on: a PGS picture says no end of its own,
  // and an empty one clears the screen.
  void add_bitmaps(const AVSubtitle& sub, double start, double end) {
    for (BitmapEvent& e : events)
      if (e.start_s < start && e.end_s > start) e.end_s = start;
    BitmapEvent event;
    event.start_s = start;
    event.end_s = end;
    for (unsigned i = 0; i < sub.num_rects; ++i) {
      const AVSubtitleRect& rect = *sub.rects[i];
      if (rect.type == SUBTITLE_BITMAP && rect.w > 0 && rect.h > 0 && rect.data[0] && rect.data[1])
        event.rects.push_back(premultiplied(rect));
    }
    if (event.rects.empty()) return;
    const auto [canvas_w, canvas_h] = bitmap_canvas(sub);
    event.canvas_w = canvas_w;
    event.canvas_h = canvas_h;
    events.push_back(std::move(event));
  }

  // The events shown at `t_s` drawn into `out`, each eye's part of the canvas scaled to the view.
  void render_bitmaps(double t_s, SubtitleBitmap& out) {
    // Those over before the time asked are not shown again without a seek, which reads anew.
    std::erase_if(events, [&](const BitmapEvent& e) { return e.end_s <= t_s - 1.0; });
    const bool per_eye = stereo != SubtitleStereo::flat;
    for (const BitmapEvent& e : events) {
      if (t_s < e.start_s || t_s >= e.end_s) continue;
      if (out.rgba.empty()) out.rgba.assign(static_cast<std::size_t>(out.width) * out.height * 4, 0);
      if (per_eye && out.right_rgba.empty()) out.right_rgba.assign(out.rgba.size(), 0);
      for (int eye = 0; eye < (per_eye ? 2 : 1); ++eye) {
        // The part of the canvas this eye sees, [sx, sx + sw) × [sy, sy + sh).
        double sx = 0, sy = 0, sw = e.canvas_w, sh = e.canvas_h;
        if (stereo == SubtitleStereo::side_by_side) {
          sw /= 2;
          sx = eye * sw;
        } else if (stereo == SubtitleStereo::top_bottom) {
          sh /= 2;
          sy = eye * sh;
        }
        std::vector<std::uint8_t>& target = eye == 0 ? out.rgba : out.right_rgba;
        const double to_view_x = out.width / sw, to_view_y = out.height / sh;
        for (const BitmapRect& rect : e.rects) {
          // The view pixels the rect covers, one more each side for the bilinear edge.
          const int x0 = std::max(0, static_cast<int>(std::floor((rect.x - sx) * to_view_x)) - 1);
          const int x1 = std::min(out.width, static_cast<int>(std::ceil((rect.x + rect.w - sx) * to_view_x)) + 1);
          const int y0 = std::max(0, static_cast<int>(std::floor((rect.y - sy) * to_view_y)) - 1);
          const int y1 = std::min(out.height, static_cast<int>(std::ceil((rect.y + rect.h - sy) * to_view_y)) + 1);
          for (int y = y0; y < y1; ++y) {
            const double cy = sy + (y + 0.5) / to_view_y;
            if (cy < sy || cy >= sy + sh) continue;
            for (int x = x0; x < x1; ++x) {
              const double cx = sx + (x + 0.5) / to_view_x;
              if (cx < sx || cx >= sx + sw) continue;
              int c[4];
              sample(rect, cx, cy, c);
              if (c[3] == 0) continue;
              // Already premultiplied: "over" is src + dst × (1 − a).
              std::uint8_t* d = &target[(static_cast<std::size_t>(y) * out.width + x) * 4];
              for (int k = 0; k < 4; ++k)
                d[k] = static_cast<std::uint8_t>(std::min(255, c[k] + (d[k] * (255 - c[3]) + 127) / 255));
            }
          }
        }
      }
    }
  }

  // Reads packets until one starts after `t_s` (kept for later) or the stream ends.
  void read_to(double t_s) {
    while (!at_end && read_until_s <= t_s) {
      const int err = av_read_frame(format.get(), packet.get());
      if (err == AVERROR_EOF) {
        at_end = true;
        break;
      }
      if (err < 0) fail(fmt::format("cannot read subtitles: {}", av_error(err)));
      if (packet->stream_index == stream->index) {
        const std::int64_t pts = packet->pts != AV_NOPTS_VALUE ? packet->pts : packet->dts;
        if (pts != AV_NOPTS_VALUE) read_until_s = std::max(read_until_s, seconds(pts));
        decode(*packet);
      }
      av_packet_unref(packet.get());
    }
  }

  // Back in time, or far ahead of what was read: read again from a little before `t_s`.
  void seek_to(double t_s) {
    constexpr double kPreroll = 10.0;  // events that began this long before the seek still show
    const double from = t_s - kPreroll;
    const auto ts = static_cast<std::int64_t>((from + offset_s) * AV_TIME_BASE);
    // Back to the start, or in a file that cannot seek there, the file is read again from its start:
    // a format that seeks by an index of what was read (a .sup) finds nothing before its first
    // packet, and lands after a display set's first segments when seeking to its time.
    const bool from_start = format->start_time == AV_NOPTS_VALUE || ts <= format->start_time;
    if (from_start || avformat_seek_file(format.get(), -1, std::numeric_limits<std::int64_t>::min(), ts, ts, 0) < 0) {
      const int index = stream->index;
      AVFormatContext* raw = nullptr;
      if (open_local(&raw, path) < 0) return;
      ffmpeg::FormatContextPtr again(raw);
      if (avformat_find_stream_info(again.get(), nullptr) < 0 || index >= static_cast<int>(again->nb_streams)) return;
      read_only_stream(*again, index);
      format = std::move(again);
      stream = format->streams[index];
    }
    avcodec_flush_buffers(codec.get());
    if (track) ass_flush_events(track.get());
    events.clear();
    at_end = false;
    read_until_s = -std::numeric_limits<double>::infinity();
  }

  void render_text(double t_s, SubtitleBitmap& out, double aspect) {
    // libass's "pixel aspect" scales glyph widths by its inverse: the storage aspect over the
    // display aspect (0.5 for a half side-by-side view), as mpv passes it.
    const double pixel_aspect_now = (static_cast<double>(out.width) / out.height) / aspect;
    if (out.width != frame_w || out.height != frame_h || pixel_aspect_now != pixel_aspect) {
      ass_set_frame_size(renderer.get(), out.width, out.height);
      ass_set_storage_size(renderer.get(), out.width, out.height);
      ass_set_pixel_aspect(renderer.get(), pixel_aspect_now);
      frame_w = out.width;
      frame_h = out.height;
      pixel_aspect = pixel_aspect_now;
    }
    bool drawn = false;
    for (ASS_Image* image = ass_render_frame(renderer.get(), track.get(), std::llround(t_s * 1000.0), nullptr); image;
         image = image->next) {
      const int r = (image->color >> 24) & 0xff, g = (image->color >> 16) & 0xff, b = (image->color >> 8) & 0xff;
      const int opacity = 255 - static_cast<int>(image->color & 0xff);
      for (int y = 0; y < image->h; ++y) {
        const int oy = image->dst_y + y;
        if (oy < 0 || oy >= out.height) continue;
        for (int x = 0; x < image->w; ++x) {
          const int ox = image->dst_x + x;
          if (ox < 0 || ox >= out.width) continue;
          const int coverage = image->bitmap[static_cast<std::size_t>(y) * image->stride + x];
          if (coverage == 0) continue;
          if (!drawn) {
            out.rgba.assign(static_cast<std::size_t>(out.width) * out.height * 4, 0);
            drawn = true;
          }
          const int a = (coverage * opacity + 127) / 255;
          blend_premultiplied(&out.rgba[(static_cast<std::size_t>(oy) * out.width + ox) * 4], r, g, b, a);
        }
      }
    }
  }
};

SubtitleTrack::SubtitleTrack(const std::string& path, double start_s, const SubtitleStreamChoice& choice)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->offset_s = start_s;
  impl_->choice = choice;
  impl_->open();
}

SubtitleTrack::~SubtitleTrack() = default;

std::vector<std::string> SubtitleTrack::beside(const std::string& movie) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path path(movie);
  if (!fs::is_regular_file(path, ec)) return {};
  const std::string stem = path.stem().string();
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::vector<std::string> exact, with_language;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, ec)) {
    const fs::path& candidate = entry.path();
    std::string ext = candidate.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext != ".srt" && ext != ".ass" && ext != ".ssa" && ext != ".vtt" && ext != ".sup" && ext != ".idx") continue;
    const std::string name = candidate.stem().string();
    if (name == stem)
      exact.push_back(candidate.string());
    else if (name.size() > stem.size() + 1 && name.compare(0, stem.size() + 1, stem + ".") == 0)
      with_language.push_back(candidate.string());
  }
  std::sort(exact.begin(), exact.end());
  std::sort(with_language.begin(), with_language.end());
  exact.insert(exact.end(), with_language.begin(), with_language.end());
  return exact;
}

std::vector<std::string> SubtitleTrack::streams(const std::string& path) {
  AVFormatContext* raw = nullptr;
  if (open_local(&raw, path) < 0) return {};
  const ffmpeg::FormatContextPtr format(raw);
  if (avformat_find_stream_info(format.get(), nullptr) < 0) return {};
  std::vector<std::string> found;
  for (unsigned i = 0; i < format->nb_streams; ++i)
    if (format->streams[i]->codecpar->codec_type == AVMEDIA_TYPE_SUBTITLE) found.push_back(stream_words(*format, i));
  return found;
}

SubtitleBitmap SubtitleTrack::render(double t_s, int width, int height, double aspect) {
  Impl& m = *impl_;
  constexpr double kFarAhead = 30.0;  // reading forward beyond this is slower than a seek
  if (t_s < m.last_asked_s - 1e-6 || (!m.at_end && std::isfinite(m.read_until_s) && t_s > m.read_until_s + kFarAhead))
    if (m.streamed()) m.seek_to(t_s);
  m.last_asked_s = t_s;
  // Packets come in decode order: one starting a little after t_s may be what ends the event at t_s.
  m.read_to(t_s + 1.0);
  SubtitleBitmap out;
  out.width = width;
  out.height = height;
  if (width <= 0 || height <= 0) return out;
  if (aspect <= 0.0) aspect = static_cast<double>(width) / height;
  if (m.bitmap)
    m.render_bitmaps(t_s, out);
  else
    m.render_text(t_s, out, aspect);
  return out;
}

void SubtitleTrack::set_stereo(SubtitleStereo stereo) {
  if (stereo != SubtitleStereo::flat && !impl_->bitmap)
    throw UserError(fmt::format("{}: --sub-stereo is for bitmap subtitles (PGS, DVB, VobSub) authored per eye; "
                                "these are text, laid out once for both eyes",
                                printable(impl_->path)),
                    2);
  impl_->stereo = stereo;
  if (stereo != SubtitleStereo::flat)
    impl_->description +=
        stereo == SubtitleStereo::side_by_side ? ", per eye side by side" : ", per eye top and bottom";
}

const std::string& SubtitleTrack::description() const { return impl_->description; }

const std::string& SubtitleTrack::path() const { return impl_->path; }

int SubtitleTrack::stream_number() const {
  int number = 0;
  for (unsigned i = 0; i <= static_cast<unsigned>(impl_->stream->index); ++i)
    if (impl_->format->streams[i]->codecpar->codec_type == AVMEDIA_TYPE_SUBTITLE) ++number;
  return number;
}

}  // namespace nelf
