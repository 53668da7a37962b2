#include "inputs/stereo_metadata.hpp"

#include <fmt/format.h>

extern "C" {
#include <libavformat/avformat.h>
#include <libavutil/frame.h>
#include <libavutil/stereo3d.h>
}

#include "core/ffmpeg_raii.hpp"

namespace nelf {

std::string_view to_string(StereoPacking packing) {
  switch (packing) {
    case StereoPacking::mono:
      return "2d";
    case StereoPacking::side_by_side:
      return "side-by-side";
    case StereoPacking::top_bottom:
      return "top-bottom";
    case StereoPacking::frame_sequence:
      return "frame-sequential";
    case StereoPacking::checkerboard:
      return "checkerboard";
    case StereoPacking::side_by_side_quincunx:
      return "side-by-side quincunx";
    case StereoPacking::lines:
      return "row-interleaved";
    case StereoPacking::columns:
      return "column-interleaved";
  }
  return "unknown";
}

MetadataLayout layout_from_stereo_metadata(const StereoMetadata& metadata, double frame_display_aspect) {
  switch (metadata.packing) {
    case StereoPacking::mono:
      return {"mono", false};
    case StereoPacking::side_by_side:
      return {frame_display_aspect >= kFullSideBySideMinAspect ? "sbs" : "sbs-half", metadata.inverted};
    case StereoPacking::top_bottom:
      return {frame_display_aspect <= kFullTopBottomMaxAspect ? "tab" : "tab-half", metadata.inverted};
    case StereoPacking::frame_sequence:
      return {"alt", metadata.inverted};
    case StereoPacking::checkerboard:
    case StereoPacking::side_by_side_quincunx:
    case StereoPacking::lines:
    case StereoPacking::columns:
      break;
  }
  throw UnsupportedStereoMetadata(
      fmt::format("the file's stereo metadata says {} 3D, which nelf cannot split into views; convert it to "
                  "side-by-side or top-bottom first, or pass --layout to override",
                  to_string(metadata.packing)));
}

namespace {

std::optional<StereoMetadata> from_av(const AVStereo3D& stereo) {
  StereoMetadata metadata;
  metadata.inverted = (stereo.flags & AV_STEREO3D_FLAG_INVERT) != 0;
  // A newer FFmpeg at run time than the headers of this build may store a type they do not list.
  switch (ffmpeg::raw_value(stereo.type)) {
    case AV_STEREO3D_2D:
      metadata.packing = StereoPacking::mono;
      break;
    case AV_STEREO3D_SIDEBYSIDE:
      metadata.packing = StereoPacking::side_by_side;
      break;
    case AV_STEREO3D_TOPBOTTOM:
      metadata.packing = StereoPacking::top_bottom;
      break;
    case AV_STEREO3D_FRAMESEQUENCE:
      metadata.packing = StereoPacking::frame_sequence;
      break;
    case AV_STEREO3D_CHECKERBOARD:
      metadata.packing = StereoPacking::checkerboard;
      break;
    case AV_STEREO3D_SIDEBYSIDE_QUINCUNX:
      metadata.packing = StereoPacking::side_by_side_quincunx;
      break;
    case AV_STEREO3D_LINES:
      metadata.packing = StereoPacking::lines;
      break;
    case AV_STEREO3D_COLUMNS:
      metadata.packing = StereoPacking::columns;
      break;
    default:
      return std::nullopt;  // a type newer than this build knows: treat as no metadata
  }
  return metadata;
}

}  // namespace

std::optional<StereoMetadata> stereo_metadata_from_stream(const AVStream& stream) {
  // FFmpeg 5.1 has no av_stereo3d_alloc_size and keeps stream side data on the AVStream
  // (DESIGN.md §12). The side data is an AVStereo3D struct; refuse anything shorter.
  size_t size = 0;
  const uint8_t* data = av_stream_get_side_data(&stream, AV_PKT_DATA_STEREO3D, &size);
  if (data == nullptr || size < sizeof(AVStereo3D)) return std::nullopt;
  return from_av(*reinterpret_cast<const AVStereo3D*>(data));
}

std::optional<StereoMetadata> stereo_metadata_from_frame(const AVFrame& frame) {
  const AVFrameSideData* side_data = av_frame_get_side_data(&frame, AV_FRAME_DATA_STEREO3D);
  if (side_data == nullptr || side_data->size < sizeof(AVStereo3D)) return std::nullopt;
  return from_av(*reinterpret_cast<const AVStereo3D*>(side_data->data));
}

}  // namespace nelf
