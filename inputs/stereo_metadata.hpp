#pragma once
// Stereo 3D metadata carried by media files (FFmpeg's AVStereo3D): Matroska StereoMode, MP4 `st3d`
// (stream side data) and the H.264 frame-packing SEI (frame side data, keyframes only). The mapping
// to nelf's layout names is a pure function so that the layout detection chain (DESIGN.md §6) can
// use it without touching FFmpeg.
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

struct AVStream;
struct AVFrame;

namespace nelf {

// What the file says, in FFmpeg's terms (AVStereo3DType), independent of FFmpeg's headers.
enum class StereoPacking {
  mono,                   // AV_STEREO3D_2D
  side_by_side,           // AV_STEREO3D_SIDEBYSIDE
  top_bottom,             // AV_STEREO3D_TOPBOTTOM
  frame_sequence,         // AV_STEREO3D_FRAMESEQUENCE
  checkerboard,           // AV_STEREO3D_CHECKERBOARD
  side_by_side_quincunx,  // AV_STEREO3D_SIDEBYSIDE_QUINCUNX
  lines,                  // AV_STEREO3D_LINES (row interleaved)
  columns,                // AV_STEREO3D_COLUMNS (column interleaved)
};

std::string_view to_string(StereoPacking packing);

struct StereoMetadata {
  StereoPacking packing = StereoPacking::mono;
  bool inverted = false;  // AV_STEREO3D_FLAG_INVERT: the right/bottom (or first) view is the left eye
  bool operator==(const StereoMetadata&) const = default;
};

// A nelf layout name (`sbs`, `sbs-half`, `tab`, `tab-half`, `alt`, `mono`) and whether to swap eyes.
struct MetadataLayout {
  std::string layout;
  bool swap_eyes = false;
  bool operator==(const MetadataLayout&) const = default;
};

// Metadata that describes a packing nelf cannot split (checkerboard, row/column interleave).
class UnsupportedStereoMetadata : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Metadata never says whether side-by-side or top-bottom views are full or half resolution, so it
// is inferred from the frame's display aspect (width x SAR / height). This is the one place those
// half/full thresholds live: the detection chain (inputs/stereo_layout.hpp) maps metadata only
// through layout_from_stereo_metadata(), and the `lr`/`rl` filename tokens use the SBS one too.
// Once something says the frame *is* stereo, the only question is half or full, so the threshold
// sits between the widest single view in practice and the narrowest doubled one:
//   side-by-side: half frames have one view's aspect (1920x1080 -> 1.78, scope at most 2.39); full
//     frames twice it (3840x1080 -> 3.56, two 4:3 views 2.67). Full when >= 2.5.
//   top-bottom: half frames have one view's aspect (1.33 .. 2.39); full frames half of it
//     (1920x2160 -> 0.89, two 2.39 scope views stacked 1.20). Full when <= 1.25.
// The aspect rule of DESIGN.md §6 (W/H >= 3 full SBS, W/H <= 1 full TAB) is deliberately stricter:
// with no other evidence it must also leave 2D frames (a 2.39 scope film, a square photo) alone.
// Every frame the aspect rule calls full, these thresholds call full as well.
inline constexpr double kFullSideBySideMinAspect = 2.5;
inline constexpr double kFullTopBottomMaxAspect = 1.25;

// Maps `metadata` to a nelf layout for a frame with the given display aspect. Throws
// UnsupportedStereoMetadata for packings nelf cannot split.
MetadataLayout layout_from_stereo_metadata(const StereoMetadata& metadata, double frame_display_aspect);

// Reads AV_PKT_DATA_STEREO3D stream side data (Matroska StereoMode, MP4 st3d); nullopt when absent.
std::optional<StereoMetadata> stereo_metadata_from_stream(const AVStream& stream);
// Reads AV_FRAME_DATA_STEREO3D frame side data (H.264/HEVC frame-packing SEI); nullopt when absent.
std::optional<StereoMetadata> stereo_metadata_from_frame(const AVFrame& frame);

}  // namespace nelf
