#pragma once
// Stereo input layouts (DESIGN.md §6): their names, how a full frame splits into two views, and the
// detection order that picks a layout when the user gives none. Pure functions, no I/O; video reuses
// them with its container metadata as extra evidence.
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/image.hpp"
#include "inputs/multiview.hpp"
#include "inputs/stereo_metadata.hpp"

namespace nelf {

enum class StereoLayout { sbs, sbs_half, tab, tab_half, fp, alt, pair, mono };

// A layout that cannot be applied: it does not fit the frame, or needs more than one frame.
// what() is one line saying what does not fit and why.
class LayoutError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "sbs", "sbs-half", "tab", "tab-half", "fp", "alt", "pair", "mono".
std::string_view to_string(StereoLayout layout);
std::optional<StereoLayout> parse_stereo_layout(std::string_view name);
const std::vector<std::string_view>& stereo_layout_names();

// The frame sizes of the HDMI 1.4a frame-packed formats accepted as `fp` input.
struct FramePackedGeometry {
  int width;
  int eye_height;
  int gap_rows;
  int height() const { return 2 * eye_height + gap_rows; }
};
std::optional<FramePackedGeometry> frame_packed_geometry(int width, int height);

// Splits one full frame into its two views. Side-by-side and top-bottom halves keep the frame's
// pixels; half layouts are anamorphic, so each view is displayed at the full frame's aspect
// (1920x1080 sbs-half -> two 960x1080 views shown at 16:9). `mono` gives the same view to both eyes.
// `swap_eyes` exchanges the two views (right-left sources). Throws LayoutError when the layout does
// not fit (odd width for side-by-side, odd height for top-bottom, fp of a size that is not a
// frame-packed format, an empty frame) or needs two frames (`alt`, `pair`).
StereoPair split_frame(const Image& frame, StereoLayout layout, bool swap_eyes = false);

// Which rule of the detection order decided (`nelf probe` prints it).
enum class DetectionRule { flag, multiview, metadata, frame_size, filename, aspect, fallback };
// "flag", "multiview", "metadata", "frame-size", "filename", "aspect", "default".
std::string_view to_string(DetectionRule rule);

// The first five fields are positional in callers: {flag, metadata, width, height, filename}.
struct LayoutEvidence {
  std::optional<StereoLayout> flag;        // the user's --layout
  std::optional<StereoMetadata> metadata;  // stream side data, else a remembered frame-packing SEI
  int width = 0;                           // the full frame's size as delivered (after rotation)
  int height = 0;
  std::filesystem::path filename;         // only the last component is looked at
  bool swap_eyes = false;                 // the user's --swap-eyes: swaps whatever was detected (XOR)
  double display_aspect = 0.0;            // width x SAR / height for video; 0 means width / height
  Multiview multiview = Multiview::none;  // a second view FFmpeg does not decode (inputs/multiview.hpp)
};

struct LayoutDecision {
  StereoLayout layout = StereoLayout::mono;
  bool swap_eyes = false;  // the source stores the right view first
  DetectionRule rule = DetectionRule::fallback;
  std::string warning;  // non-empty when the result is a guess the user should know about
};

// Detection order: explicit flag -> a multiview stream (H.264 MVC, MV-HEVC: only its base view
// decodes, so mono with a warning that says why) -> metadata (layout_from_stereo_metadata: half or full from the
// display aspect, see kFullSideBySideMinAspect) -> exact HDMI frame-packed frame size -> filename
// tokens -> aspect (W/H >= 3 full SBS, W/H <= 1 full TAB) -> mono with a warning.
// `.jps` files store right-left side-by-side by convention: they are sbs when nothing else says
// otherwise, and their views are swapped whatever rule decided the layout. `evidence.swap_eyes`
// (--swap-eyes) swaps on top of all that. Throws UnsupportedStereoMetadata when the metadata names
// a packing nelf cannot split (checkerboard, interleaved) and no flag overrides it.
LayoutDecision detect_stereo_layout(const LayoutEvidence& evidence);

// The filename rule alone: release-name tokens (any case, delimited by non-alphanumerics, in the
// last path component only). Explicit spellings decide half or full: `hsbs`, `h-sbs`, `half-sbs`,
// `halfsbs` are sbs-half; `fsbs`, `f-sbs`, `full-sbs`, `fullsbs` sbs; `htab`, `hou`, `h-ou`,
// `half-ou`, `halftab`... tab-half; `ftab`, `fou`, `full-ou`, `fulltab`... tab. A bare `sbs`, `ou`,
// `tab`, `lr`, `rl` or `3d` says only the arrangement (`3d` and `lr`/`rl` side-by-side, `rl`
// swapped): with a known `display_aspect` (> 0) half or full is decided as for metadata
// (kFullSideBySideMinAspect, kFullTopBottomMaxAspect), so "Movie.1080p.3D.SBS.mkv" at 1920x1080
// is sbs-half and at 3840x1080 sbs; with no aspect they mean full, `3d` half.
// Returns nothing when no token names a layout.
struct FilenameLayout {
  StereoLayout layout;
  bool swap_eyes = false;
};
std::optional<FilenameLayout> layout_from_filename(const std::filesystem::path& filename, double display_aspect = 0.0);

}  // namespace nelf
