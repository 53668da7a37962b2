#include "inputs/file_carried_streams.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/user_error.hpp"
#include "inputs/ffmpeg_input.hpp"

namespace nelf {
namespace {

// How long before the start point a subtitle still on screen there may have begun (a song's lyric
// or a sign stays up for a minute at most).
constexpr double kLongestSubtitleS = 60.0;

// `packet` (a subtitle event, already at output time) cut to [0, end_s).
void cut_subtitle(AVPacket& packet, AVRational time_base, std::optional<double> end_s) {
  if (packet.pts == AV_NOPTS_VALUE) return;
  std::int64_t end = packet.duration > 0 ? packet.pts + packet.duration : packet.pts;
  if (end_s) end = std::min(end, static_cast<std::int64_t>(std::llround(*end_s / av_q2d(time_base))));
  if (packet.pts < 0) packet.pts = 0;
  packet.dts = packet.pts;
  if (packet.duration > 0) packet.duration = std::max<std::int64_t>(end - packet.pts, 1);
}

class FileCarriedStreams final : public CarriedStreams {
 public:
  FileCarriedStreams(const std::string& path, double origin_s, bool allow_network) : origin_s_(origin_s) {
    network_.allow_network = allow_network;
    const int opened = ffmpeg::open_input(format_, path, network_);
    if (const auto stopped = ffmpeg::guard_stop(path, network_)) throw UserError(*stopped, 1);
    if (opened < 0)
      throw UserError(fmt::format("{}: cannot reopen for audio: {}", path, ffmpeg::error_string(opened)), 1);
    const int found = ffmpeg::find_stream_info(format_.get(), network_);
    if (const auto stopped = ffmpeg::guard_stop(path, network_)) throw UserError(*stopped, 1);
    if (found < 0) throw UserError(fmt::format("{}: cannot read stream information", path), 1);
    layout_ = describe_carried_streams(*format_);
    const bool subtitles = std::any_of(layout_.streams.begin(), layout_.streams.end(), [](const CarriedStream& c) {
      return c.codec->codec_type == AVMEDIA_TYPE_SUBTITLE;
    });
    // A subtitle on screen at the start point began before it: reading starts that much earlier
    // so that its event is found and shown from 0 (packets before 0 are left out or cut).
    const double seek_s = origin_s - (subtitles ? kLongestSubtitleS : 0.0);
    const double file_start_s =
        format_->start_time == AV_NOPTS_VALUE ? 0.0 : format_->start_time / static_cast<double>(AV_TIME_BASE);
    if (seek_s > file_start_s + 0.001)
      av_seek_frame(format_.get(), -1, static_cast<std::int64_t>(seek_s * AV_TIME_BASE), AVSEEK_FLAG_BACKWARD);
    std::optional<double> end_s;
    if (format_->duration > 0) end_s = file_start_s + format_->duration / static_cast<double>(AV_TIME_BASE) - origin_s;
    layout_.chapters = chapters_in_range(std::move(layout_.chapters), origin_s, end_s);
  }

  const CarriedStreamLayout& layout() const override { return layout_; }

  ffmpeg::PacketPtr next_packet(std::span<const int> wanted, std::optional<double> until_s,
                                std::optional<double> end_s) override {
    if (wanted.empty() || done_) return nullptr;
    for (;;) {
      if (!packet_) {
        packet_.reset(av_packet_alloc());
        if (av_read_frame(format_.get(), packet_.get()) < 0) {
          done_ = true;
          packet_.reset();
          return nullptr;
        }
      }
      const AVStream* stream = format_->streams[packet_->stream_index];
      const std::int64_t ts = packet_->pts != AV_NOPTS_VALUE ? packet_->pts : packet_->dts;
      const double t = ts == AV_NOPTS_VALUE ? 0.0 : ts * av_q2d(stream->time_base) - origin_s_;
      const bool is_wanted = std::find(wanted.begin(), wanted.end(), packet_->stream_index) != wanted.end();
      // Only a carried packet waits for later: in MPEG-TS the audio lies behind the video in the
      // file (the muxer gathers several audio frames per PES packet), so stopping at a video
      // packet would leave out audio that belongs before it.
      if (is_wanted && until_s && t > *until_s) return nullptr;  // keep it for later
      const bool subtitle = stream->codecpar->codec_type == AVMEDIA_TYPE_SUBTITLE;
      const double length = std::max<std::int64_t>(packet_->duration, 0) * av_q2d(stream->time_base);
      // A subtitle event is cut to the range: one on screen at the start point shows from 0.
      const bool starts_inside = t >= -1e-6 || (subtitle && t + length > 1e-6);
      // An audio packet that would play past the end is left out: the output ends with its video
      // (its container's duration is the video's), the sound at most one audio frame earlier.
      const bool ends_inside = subtitle || !end_s || length <= 0.0 || t + length <= *end_s + 1e-3;
      if (is_wanted && starts_inside && ends_inside && (!end_s || t < *end_s)) {
        // Shift to output time (the conversion starts at 0).
        const std::int64_t shift = std::llround(origin_s_ / av_q2d(stream->time_base));
        if (packet_->pts != AV_NOPTS_VALUE) packet_->pts -= shift;
        if (packet_->dts != AV_NOPTS_VALUE) packet_->dts -= shift;
        if (subtitle) cut_subtitle(*packet_, stream->time_base, end_s);
        return std::move(packet_);
      }
      packet_.reset();
    }
  }

 private:
  ffmpeg::InputGuard network_;  // before `format_`: the context points at it while it lives
  ffmpeg::FormatContextPtr format_;
  CarriedStreamLayout layout_;
  ffmpeg::PacketPtr packet_;  // read and not yet handed out
  double origin_s_;
  bool done_ = false;
};

}  // namespace

std::unique_ptr<CarriedStreams> open_file_carried_streams(const std::string& path, double origin_s,
                                                          bool allow_network) {
  return std::make_unique<FileCarriedStreams>(path, origin_s, allow_network);
}

}  // namespace nelf
