#include "inputs/audio_source.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/channel_layout.h>
#include <libswresample/swresample.h>
}

#include "core/ffmpeg_raii.hpp"
#include "inputs/ffmpeg_input.hpp"

namespace nelf {

namespace {

struct SwrContextDeleter {
  void operator()(SwrContext* s) const { swr_free(&s); }
};
using SwrContextPtr = std::unique_ptr<SwrContext, SwrContextDeleter>;

[[noreturn]] void fail_on(const std::string& path, const std::string& why) {
  throw AudioError(fmt::format("{}: {}", path, why));
}

// Opens `path` and reads its streams' parameters.
void open_container(const std::string& path, bool allow_network, ffmpeg::InputGuard& network,
                    ffmpeg::FormatContextPtr& format) {
  // The same rule as VideoSource (DESIGN.md §11): no network unless asked for.
  network.allow_network = allow_network;
  const int opened = ffmpeg::open_input(format, path, network);
  if (const auto stopped = ffmpeg::guard_stop(path, network)) throw AudioError(*stopped);
  if (opened < 0) fail_on(path, fmt::format("cannot open: {}", ffmpeg::error_string(opened)));
  const int found = ffmpeg::find_stream_info(format.get(), network);
  if (const auto stopped = ffmpeg::guard_stop(path, network)) throw AudioError(*stopped);
  if (found < 0) fail_on(path, fmt::format("not a readable media file: {}", ffmpeg::error_string(found)));
}

// The container indices of the audio streams, in the file's order: track N is the N-th.
std::vector<int> audio_stream_indices(const AVFormatContext& format) {
  std::vector<int> audio;
  for (unsigned i = 0; i < format.nb_streams; ++i)
    if (format.streams[i]->codecpar->codec_type == AVMEDIA_TYPE_AUDIO) audio.push_back(static_cast<int>(i));
  return audio;
}

}  // namespace

AVChannelLayout sdl_channel_layout(int channels) {
  // SDL2's interleaved order for 1 to 8 channels (SDL_audio.h) is FFmpeg's native order of these
  // channel masks, so the resampler writes each channel where SDL plays it.
  static constexpr std::uint64_t masks[] = {
      AV_CH_LAYOUT_MONO,
      AV_CH_LAYOUT_STEREO,
      AV_CH_LAYOUT_2POINT1,                      // FL FR LFE
      AV_CH_LAYOUT_QUAD,                         // FL FR BL BR
      AV_CH_LAYOUT_QUAD | AV_CH_LOW_FREQUENCY,   // FL FR LFE BL BR
      AV_CH_LAYOUT_5POINT1,                      // FL FR FC LFE SL SR
      AV_CH_LAYOUT_5POINT1 | AV_CH_BACK_CENTER,  // FL FR FC LFE BC SL SR
      AV_CH_LAYOUT_7POINT1,                      // FL FR FC LFE BL BR SL SR
  };
  AVChannelLayout layout{};
  av_channel_layout_from_mask(&layout, masks[std::clamp(channels, 1, 8) - 1]);
  return layout;
}

struct AudioSource::Impl {
  std::string path;
  AudioSourceOptions options;
  ffmpeg::InputGuard network;  // before `format`: the context points at it while it lives
  ffmpeg::FormatContextPtr format;
  ffmpeg::CodecContextPtr codec;
  ffmpeg::PacketPtr packet{av_packet_alloc()};
  ffmpeg::FramePtr frame{av_frame_alloc()};
  SwrContextPtr swr;
  AVStream* stream = nullptr;
  bool draining = false, finished = false;
  std::int64_t errors = 0;
  int consecutive_errors = 0;
  std::optional<double> cut_before;  // after a seek: drop samples before this time
  std::optional<double> next_pts;    // continues the timeline when a frame has no timestamp

  [[noreturn]] void fail(const std::string& why) const { throw AudioError(fmt::format("{}: {}", path, why)); }

  void open(const std::string& p, const AudioSourceOptions& o) {
    path = p;
    options = o;
    if (options.sample_rate <= 0) fail("the audio sample rate must be > 0");
    if (options.channels <= 0 || options.channels > 8) fail("the audio channel count must be 1 to 8");
    open_container(path, options.allow_network, network, format);
    const AVCodec* decoder = nullptr;
    int best = av_find_best_stream(format.get(), AVMEDIA_TYPE_AUDIO, -1, -1, &decoder, 0);
    if (best == AVERROR_STREAM_NOT_FOUND) fail("no audio stream");
    if (options.track > 0) {
      const std::vector<int> audio = audio_stream_indices(*format);
      if (options.track > static_cast<int>(audio.size()))
        fail(fmt::format("no audio track {} (the file has {})", options.track, audio.size()));
      best = audio[static_cast<std::size_t>(options.track - 1)];
      decoder = avcodec_find_decoder(format->streams[best]->codecpar->codec_id);
    }
    if (best < 0 || !decoder) fail(fmt::format("no decoder for the audio stream: {}", ffmpeg::error_string(best)));
    stream = format->streams[best];
    for (unsigned i = 0; i < format->nb_streams; ++i)
      if (static_cast<int>(i) != best) format->streams[i]->discard = AVDISCARD_ALL;
    codec.reset(avcodec_alloc_context3(decoder));
    if (!codec) fail("out of memory");
    if (avcodec_parameters_to_context(codec.get(), stream->codecpar) < 0) fail("bad audio stream parameters");
    codec->pkt_timebase = stream->time_base;
    if (const int r = avcodec_open2(codec.get(), decoder, nullptr); r < 0)
      fail(fmt::format("cannot open the {} audio decoder: {}", decoder->name, ffmpeg::error_string(r)));
  }

  // (Re)creates the resampler for the layout/format/rate of `f` (they may change mid-stream).
  void ensure_resampler(const AVFrame& f) {
    if (swr) return;
    AVChannelLayout in_layout{};
    if (f.ch_layout.order == AV_CHANNEL_ORDER_UNSPEC || f.ch_layout.nb_channels <= 0)
      av_channel_layout_default(&in_layout, std::max(1, f.ch_layout.nb_channels));
    else if (av_channel_layout_copy(&in_layout, &f.ch_layout) < 0)
      fail("cannot read the audio channel layout");
    AVChannelLayout out_layout = sdl_channel_layout(options.channels);
    SwrContext* raw = nullptr;
    const int r = swr_alloc_set_opts2(&raw, &out_layout, AV_SAMPLE_FMT_FLT, options.sample_rate, &in_layout,
                                      static_cast<AVSampleFormat>(f.format), f.sample_rate, 0, nullptr);
    av_channel_layout_uninit(&in_layout);
    av_channel_layout_uninit(&out_layout);
    swr.reset(raw);
    if (r < 0 || swr_init(swr.get()) < 0)
      fail(options.channels == 2 ? "cannot convert the audio to stereo float"
                                 : fmt::format("cannot convert the audio to {}-channel float", options.channels));
  }

  std::optional<AudioChunk> convert(const AVFrame& f) {
    ensure_resampler(f);
    const std::int64_t ts = f.best_effort_timestamp;
    // Samples still inside the resampler belong before this frame.
    const double buffered_s = static_cast<double>(swr_get_delay(swr.get(), options.sample_rate)) / options.sample_rate;
    double pts;
    if (ts != AV_NOPTS_VALUE)
      pts = ts * av_q2d(stream->time_base) - options.origin_s - buffered_s;
    else
      pts = next_pts.value_or(0.0);
    const int capacity = swr_get_out_samples(swr.get(), f.nb_samples);
    if (capacity < 0) fail("cannot convert the audio");
    const auto channels = static_cast<std::size_t>(options.channels);
    AudioChunk chunk;
    chunk.channels = options.channels;
    chunk.samples.resize(static_cast<std::size_t>(capacity) * channels);
    auto* out = reinterpret_cast<std::uint8_t*>(chunk.samples.data());
    const int converted =
        swr_convert(swr.get(), &out, capacity, const_cast<const std::uint8_t**>(f.extended_data), f.nb_samples);
    if (converted < 0) {
      ++errors;
      return std::nullopt;
    }
    chunk.samples.resize(static_cast<std::size_t>(converted) * channels);
    chunk.pts_s = pts;
    next_pts = pts + static_cast<double>(converted) / options.sample_rate;
    if (cut_before) {
      const double end = *next_pts;
      if (end <= *cut_before) return AudioChunk{pts, {}, options.channels};
      if (pts < *cut_before) {
        const auto skip = static_cast<std::size_t>(std::lround((*cut_before - pts) * options.sample_rate));
        chunk.samples.erase(chunk.samples.begin(), chunk.samples.begin() + static_cast<std::ptrdiff_t>(std::min(
                                                                               skip * channels, chunk.samples.size())));
        chunk.pts_s = pts + static_cast<double>(skip) / options.sample_rate;
      }
      cut_before.reset();
    }
    return chunk;
  }

  std::optional<AudioChunk> next() {
    while (!finished) {
      const int received = avcodec_receive_frame(codec.get(), frame.get());
      if (received == 0) {
        consecutive_errors = 0;
        if (frame->decode_error_flags != 0 || (frame->flags & AV_FRAME_FLAG_CORRUPT) != 0) ++errors;
        auto chunk = convert(*frame);
        av_frame_unref(frame.get());
        if (chunk && !chunk->samples.empty()) return chunk;
        continue;
      }
      if (received == AVERROR_EOF) {
        finished = true;
        break;
      }
      if (received != AVERROR(EAGAIN)) {
        ++errors;
        if (++consecutive_errors > 1000) fail("the audio decoder keeps failing");
        continue;
      }
      if (draining) {
        finished = true;
        break;
      }
      const int read = av_read_frame(format.get(), packet.get());
      if (read < 0) {
        draining = true;
        avcodec_send_packet(codec.get(), nullptr);
        continue;
      }
      if (packet->stream_index == stream->index) {
        const int sent = avcodec_send_packet(codec.get(), packet.get());
        if (sent < 0 && sent != AVERROR(EAGAIN)) {
          ++errors;  // a damaged packet: skip it, the next one may decode
          if (++consecutive_errors > 1000) fail("the audio decoder keeps failing");
        }
      }
      av_packet_unref(packet.get());
    }
    return std::nullopt;
  }

  void seek(double seconds) {
    seconds = std::max(0.0, seconds);
    const double target = seconds + options.origin_s;
    const auto ts = static_cast<std::int64_t>(std::floor(target / av_q2d(stream->time_base)));
    if (av_seek_frame(format.get(), stream->index, ts, AVSEEK_FLAG_BACKWARD) < 0)
      fail(fmt::format("cannot seek the audio to {:.3f} s", seconds));
    avcodec_flush_buffers(codec.get());
    swr.reset();  // drops what it had buffered from before the seek
    draining = finished = false;
    consecutive_errors = 0;
    next_pts.reset();
    cut_before = seconds;
  }
};

bool AudioSource::has_audio(const std::string& path, bool allow_network) {
  try {
    AudioSource source(path, AudioSourceOptions{48000, 0.0, allow_network});
    return true;
  } catch (const AudioError&) {
    return false;
  }
}

AudioSource::AudioSource(const std::string& path, AudioSourceOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->open(path, options);
}
AudioSource::~AudioSource() = default;
AudioSource::AudioSource(AudioSource&&) noexcept = default;
AudioSource& AudioSource::operator=(AudioSource&&) noexcept = default;

std::optional<AudioChunk> AudioSource::next() { return impl_->next(); }
void AudioSource::seek(double seconds) { impl_->seek(seconds); }
int AudioSource::sample_rate() const { return impl_->options.sample_rate; }
int AudioSource::channels() const { return impl_->options.channels; }
std::string AudioSource::codec_name() const { return impl_->codec->codec->name; }
std::int64_t AudioSource::decode_errors() const { return impl_->errors; }

std::vector<AudioTrack> file_audio_tracks(const std::string& path, bool allow_network) {
  ffmpeg::InputGuard network;
  ffmpeg::FormatContextPtr format;
  try {
    open_container(path, allow_network, network, format);
  } catch (const AudioError&) {
    return {};
  }
  const int best = av_find_best_stream(format.get(), AVMEDIA_TYPE_AUDIO, -1, -1, nullptr, 0);
  std::vector<AudioTrack> tracks;
  for (const int index : audio_stream_indices(*format)) {
    const AVStream& stream = *format->streams[index];
    AudioTrack track;
    track.number = static_cast<int>(tracks.size()) + 1;
    if (const AVDictionaryEntry* language = av_dict_get(stream.metadata, "language", nullptr, 0))
      track.language = language->value;
    track.codec = avcodec_get_name(stream.codecpar->codec_id);
    track.channels = stream.codecpar->ch_layout.nb_channels;
    track.is_default = index == best;
    tracks.push_back(std::move(track));
  }
  return tracks;
}

OpenedAudio open_file_audio(const std::string& path, double origin_s, bool allow_network, AudioFormat format) {
  AudioSourceOptions options;
  options.track = format.track;
  options.origin_s = origin_s;
  options.allow_network = allow_network;
  if (format.sample_rate > 0) options.sample_rate = format.sample_rate;
  if (format.channels > 0) options.channels = format.channels;
  try {
    return {std::make_unique<AudioSource>(path, options), {}};
  } catch (const AudioError& e) {
    return {nullptr, std::string(e.what()).find("no audio stream") != std::string::npos
                         ? "no audio stream"
                         : fmt::format("the audio cannot be decoded ({})", e.what())};
  }
}

}  // namespace nelf
