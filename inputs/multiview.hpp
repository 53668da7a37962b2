#pragma once
// Stereo video coded as a base view and a second view that refers to it (DESIGN.md §6): H.264 MVC
// (Blu-ray 3D; in M2TS a sub-stream of its own, in MKV and raw streams NAL units of types 15 and 20
// among the base view's) and MV-HEVC (Apple's spatial video: NAL units of nuh_layer_id 1 in the
// same stream). FFmpeg 5.1 decodes the base view only and says nothing about the second one, so
// nelf reads it from the codec parameters and the NAL unit headers of the first packets.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

struct AVCodecParameters;

namespace nelf {

enum class Multiview { none, h264_mvc, mv_hevc };

// "H.264 MVC", "MV-HEVC", "none".
std::string_view to_string(Multiview multiview);

// What the stream's parameters say: an H.264 stream of a multiview profile (118 Multiview High,
// 128 Stereo High: the dependent view's sub-stream), or extradata holding a subset SPS (H.264) or a
// parameter set of a layer above 0 (HEVC).
Multiview multiview_from_codec(const AVCodecParameters& codec);

// What one packet of a stream with these parameters says: an H.264 subset SPS (15) or MVC slice
// extension (20), an HEVC NAL unit of a layer above 0. The packet is Annex B (start codes) or, when
// the extradata is avcC/hvcC (MP4, Matroska), NAL units with a length before each.
Multiview multiview_from_packet(const AVCodecParameters& codec, std::span<const std::uint8_t> packet);

}  // namespace nelf
