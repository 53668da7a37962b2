#include "inputs/multiview.hpp"

#include <functional>
#include <optional>

extern "C" {
#include <libavcodec/avcodec.h>
}

namespace nelf {
namespace {

constexpr int kH264SubsetSps = 15;
constexpr int kH264SliceExtension = 20;
constexpr int kH264MultiviewHigh = 118;
constexpr int kH264StereoHigh = 128;

using NalVisitor = std::function<bool(std::span<const std::uint8_t>)>;  // true: stop

// Each NAL unit after a start code (00 00 01) of `data`; true when `visit` stopped.
bool visit_annex_b(std::span<const std::uint8_t> data, const NalVisitor& visit) {
  std::size_t i = 0;
  std::optional<std::size_t> start;
  const auto emit = [&](std::size_t end) { return start && end > *start && visit(data.subspan(*start, end - *start)); };
  while (i + 3 <= data.size()) {
    if (data[i] == 0 && data[i + 1] == 0 && data[i + 2] == 1) {
      std::size_t end = i;
      while (end > 0 && start && end > *start && data[end - 1] == 0) --end;  // the 4-byte start code's zero
      if (emit(end)) return true;
      start = i + 3;
      i += 3;
    } else {
      ++i;
    }
  }
  return emit(data.size());
}

// Each NAL unit of `data`, each after its length in `length_size` big-endian bytes.
bool visit_length_prefixed(std::span<const std::uint8_t> data, int length_size, const NalVisitor& visit) {
  std::size_t i = 0;
  while (i + static_cast<std::size_t>(length_size) <= data.size()) {
    std::size_t length = 0;
    for (int b = 0; b < length_size; ++b) length = (length << 8) | data[i + static_cast<std::size_t>(b)];
    i += static_cast<std::size_t>(length_size);
    if (length == 0 || length > data.size() - i) return false;  // damaged: nothing more to read
    if (visit(data.subspan(i, length))) return true;
    i += length;
  }
  return false;
}

bool is_h264_multiview_nal(std::span<const std::uint8_t> nal) {
  if (nal.empty()) return false;
  const int type = nal[0] & 0x1f;
  return type == kH264SubsetSps || type == kH264SliceExtension;
}

bool is_hevc_upper_layer_nal(std::span<const std::uint8_t> nal) {
  // forbidden_zero_bit(1) nal_unit_type(6) nuh_layer_id(6) nuh_temporal_id_plus1(3)
  return nal.size() >= 2 && (((nal[0] & 1) << 5) | (nal[1] >> 3)) > 0;
}

// The NAL length size of avcC/hvcC extradata; 0 for Annex B (or none).
int nal_length_size(const AVCodecParameters& codec) {
  const std::span<const std::uint8_t> extra(codec.extradata, codec.extradata ? codec.extradata_size : 0);
  if (extra.empty() || extra[0] != 1) return 0;  // configurationVersion 1: avcC / hvcC
  if (codec.codec_id == AV_CODEC_ID_H264 && extra.size() >= 7) return (extra[4] & 3) + 1;
  if (codec.codec_id == AV_CODEC_ID_HEVC && extra.size() >= 23) return (extra[21] & 3) + 1;
  return 0;
}

// The parameter sets of hvcC extradata (ISO/IEC 14496-15 §8.3.3).
bool visit_hvcc(std::span<const std::uint8_t> extra, const NalVisitor& visit) {
  std::size_t i = 23;
  for (int array = 0, arrays = extra[22]; array < arrays; ++array) {
    if (i + 3 > extra.size()) return false;
    const std::size_t count = (static_cast<std::size_t>(extra[i + 1]) << 8) | extra[i + 2];
    i += 3;
    for (std::size_t n = 0; n < count; ++n) {
      if (i + 2 > extra.size()) return false;
      const std::size_t length = (static_cast<std::size_t>(extra[i]) << 8) | extra[i + 1];
      i += 2;
      if (length > extra.size() - i) return false;
      if (visit(extra.subspan(i, length))) return true;
      i += length;
    }
  }
  return false;
}

Multiview kind_of(AVCodecID id) {
  return id == AV_CODEC_ID_H264 ? Multiview::h264_mvc : id == AV_CODEC_ID_HEVC ? Multiview::mv_hevc : Multiview::none;
}

NalVisitor detector(AVCodecID id) {
  return id == AV_CODEC_ID_H264 ? NalVisitor(is_h264_multiview_nal) : NalVisitor(is_hevc_upper_layer_nal);
}

}  // namespace

std::string_view to_string(Multiview multiview) {
  switch (multiview) {
    case Multiview::none:
      return "none";
    case Multiview::h264_mvc:
      return "H.264 MVC";
    case Multiview::mv_hevc:
      return "MV-HEVC";
  }
  return "none";
}

Multiview multiview_from_codec(const AVCodecParameters& codec) {
  const Multiview kind = kind_of(codec.codec_id);
  if (kind == Multiview::none) return kind;
  if (kind == Multiview::h264_mvc && (codec.profile == kH264MultiviewHigh || codec.profile == kH264StereoHigh))
    return kind;
  const std::span<const std::uint8_t> extra(codec.extradata, codec.extradata ? codec.extradata_size : 0);
  if (extra.empty()) return Multiview::none;
  const NalVisitor visit = detector(codec.codec_id);
  if (nal_length_size(codec) == 0) return visit_annex_b(extra, visit) ? kind : Multiview::none;
  if (kind == Multiview::mv_hevc) return visit_hvcc(extra, visit) ? kind : Multiview::none;
  return Multiview::none;  // avcC holds the base view's SPS and PPS only
}

Multiview multiview_from_packet(const AVCodecParameters& codec, std::span<const std::uint8_t> packet) {
  const Multiview kind = kind_of(codec.codec_id);
  if (kind == Multiview::none || packet.empty()) return Multiview::none;
  const NalVisitor visit = detector(codec.codec_id);
  const int length_size = nal_length_size(codec);
  const bool found =
      length_size == 0 ? visit_annex_b(packet, visit) : visit_length_prefixed(packet, length_size, visit);
  return found ? kind : Multiview::none;
}

}  // namespace nelf
