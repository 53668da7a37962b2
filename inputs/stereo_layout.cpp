#include "inputs/stereo_layout.hpp"

#include "inputs/view_regions.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <utility>

namespace nelf {
namespace {

struct LayoutName {
  StereoLayout layout;
  std::string_view name;
};
constexpr std::array<LayoutName, 8> kLayoutNames{{
    {StereoLayout::sbs, "sbs"},
    {StereoLayout::sbs_half, "sbs-half"},
    {StereoLayout::tab, "tab"},
    {StereoLayout::tab_half, "tab-half"},
    {StereoLayout::fp, "fp"},
    {StereoLayout::alt, "alt"},
    {StereoLayout::pair, "pair"},
    {StereoLayout::mono, "mono"},
}};

// The two HDMI 1.4a frame-packed formats (DESIGN.md §7): the gap is the vertical blanking of one eye.
constexpr std::array<FramePackedGeometry, 2> kFramePacked{{{1280, 720, 30}, {1920, 1080, 45}}};

// Copies the w x h block at (x0, y0) of `frame`.
Image crop(const Image& frame, int x0, int y0, int w, int h) {
  Image out(w, h);
  for (int y = 0; y < h; ++y) {
    const Rgba* src = &frame.at(x0, y0 + y);
    std::copy(src, src + w, &out.at(0, y));
  }
  return out;
}

double ratio(int w, int h) { return static_cast<double>(w) / static_cast<double>(h); }

// The aspect rule of DESIGN.md §6, used only when nothing else says the frame is stereo: a full
// SBS frame is at least 3:1 (two 16:9 views are 3.56:1), a full TAB frame at most 1:1. Metadata and
// `lr`/`rl` tokens, which do say stereo, use the looser half/full thresholds of stereo_metadata.hpp.
bool aspect_says_full_side_by_side(double aspect) { return aspect >= 3.0; }
bool aspect_says_full_top_bottom(double aspect) { return aspect > 0.0 && aspect <= 1.0; }

std::string lowercase(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::vector<std::string> alphanumeric_tokens(std::string_view text) {
  std::vector<std::string> tokens;
  std::string current;
  for (char c : text) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      current += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!current.empty()) {
      tokens.push_back(std::move(current));
      current.clear();
    }
  }
  if (!current.empty()) tokens.push_back(std::move(current));
  return tokens;
}

bool is_jps(const std::filesystem::path& filename) { return lowercase(filename.extension().string()) == ".jps"; }

}  // namespace

std::string_view to_string(StereoLayout layout) {
  for (const auto& entry : kLayoutNames)
    if (entry.layout == layout) return entry.name;
  return "unknown";
}

std::optional<StereoLayout> parse_stereo_layout(std::string_view name) {
  for (const auto& entry : kLayoutNames)
    if (entry.name == name) return entry.layout;
  return std::nullopt;
}

const std::vector<std::string_view>& stereo_layout_names() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> v;
    for (const auto& entry : kLayoutNames) v.push_back(entry.name);
    return v;
  }();
  return names;
}

std::optional<FramePackedGeometry> frame_packed_geometry(int width, int height) {
  for (const auto& g : kFramePacked)
    if (g.width == width && g.height() == height) return g;
  return std::nullopt;
}

StereoPair split_frame(const Image& frame, StereoLayout layout, bool swap_eyes) {
  const ViewRegions r = view_regions(layout, frame.width(), frame.height(), swap_eyes);
  const auto view = [&](const PixelRect& rect) {
    return View{crop(frame, rect.x, rect.y, rect.width, rect.height), r.display_aspect};
  };
  return StereoPair{view(r.left), view(r.right)};
}

std::string_view to_string(DetectionRule rule) {
  switch (rule) {
    case DetectionRule::flag:
      return "flag";
    case DetectionRule::multiview:
      return "multiview";
    case DetectionRule::metadata:
      return "metadata";
    case DetectionRule::frame_size:
      return "frame-size";
    case DetectionRule::filename:
      return "filename";
    case DetectionRule::aspect:
      return "aspect";
    case DetectionRule::fallback:
      return "default";
  }
  return "unknown";
}

std::optional<FilenameLayout> layout_from_filename(const std::filesystem::path& filename, double display_aspect) {
  // A bare `sbs`/`ou`/`tab` (and `lr`, `rl`, `3d`) names only the arrangement: most "1080p.3D.SBS"
  // releases are half width, so half or full is decided from the frame's aspect exactly as for
  // metadata. With no aspect known `sbs`/`tab`/`lr`/`rl` mean full (the common stills convention)
  // and `3d` half. Only the explicit half/full spellings override the aspect.
  const bool aspect_known = display_aspect > 0.0;
  const StereoLayout side_by_side =
      aspect_known && display_aspect < kFullSideBySideMinAspect ? StereoLayout::sbs_half : StereoLayout::sbs;
  const StereoLayout top_bottom =
      aspect_known && display_aspect > kFullTopBottomMaxAspect ? StereoLayout::tab_half : StereoLayout::tab;
  const auto tokens = alphanumeric_tokens(filename.filename().string());
  bool says_3d = false;
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const std::string& t = tokens[i];
    const std::string next = i + 1 < tokens.size() ? tokens[i + 1] : std::string();
    const bool next_sbs = next == "sbs";
    const bool next_tab = next == "tab" || next == "ou";
    // Two-token spellings first: "half-sbs", "h.sbs", "half_ou", "full-sbs", "f-sbs", "full.tab".
    if (t == "h" || t == "half") {
      if (next_sbs) return FilenameLayout{StereoLayout::sbs_half};
      if (next_tab) return FilenameLayout{StereoLayout::tab_half};
    }
    if (t == "f" || t == "full") {
      if (next_sbs) return FilenameLayout{StereoLayout::sbs};
      if (next_tab) return FilenameLayout{StereoLayout::tab};
    }
    if (t == "hsbs" || t == "halfsbs") return FilenameLayout{StereoLayout::sbs_half};
    if (t == "fsbs" || t == "fullsbs") return FilenameLayout{StereoLayout::sbs};
    if (t == "htab" || t == "hou" || t == "halftab" || t == "halfou") return FilenameLayout{StereoLayout::tab_half};
    if (t == "ftab" || t == "fou" || t == "fulltab" || t == "fullou") return FilenameLayout{StereoLayout::tab};
    if (t == "sbs") return FilenameLayout{side_by_side};
    if (t == "tab" || t == "ou") return FilenameLayout{top_bottom};
    if (t == "lr") return FilenameLayout{side_by_side};
    if (t == "rl") return FilenameLayout{side_by_side, true};
    if (t == "3d") says_3d = true;
  }
  // "3D" with nothing more specific: release groups mean side-by-side by it, half unless the
  // frame's aspect says full.
  if (says_3d) return FilenameLayout{aspect_known ? side_by_side : StereoLayout::sbs_half};
  return std::nullopt;
}

LayoutDecision detect_stereo_layout(const LayoutEvidence& evidence) {
  const int w = evidence.width, h = evidence.height;
  const double aspect = evidence.display_aspect > 0.0 ? evidence.display_aspect : h > 0 ? ratio(w, h) : 0.0;
  LayoutDecision decision = [&]() -> LayoutDecision {
    if (evidence.flag) return {*evidence.flag, false, DetectionRule::flag, {}};
    if (evidence.multiview != Multiview::none)
      return {StereoLayout::mono, false, DetectionRule::multiview,
              fmt::format("{}: {} stereo: FFmpeg decodes only its base view, so it plays in 2D (that view to both "
                          "eyes)",
                          evidence.filename.filename().string(), to_string(evidence.multiview))};
    if (evidence.metadata) {
      // Throws UnsupportedStereoMetadata for packings nelf cannot split.
      const MetadataLayout m = layout_from_stereo_metadata(*evidence.metadata, aspect);
      const auto layout = parse_stereo_layout(m.layout);
      if (!layout) throw std::logic_error("layout_from_stereo_metadata gave an unknown layout " + m.layout);
      return {*layout, m.swap_eyes, DetectionRule::metadata, {}};
    }
    if (frame_packed_geometry(w, h)) return {StereoLayout::fp, false, DetectionRule::frame_size, {}};
    if (auto named = layout_from_filename(evidence.filename, aspect))
      return {named->layout, named->swap_eyes, DetectionRule::filename, {}};
    if (is_jps(evidence.filename)) return {StereoLayout::sbs, false, DetectionRule::filename, {}};
    if (aspect_says_full_side_by_side(aspect)) return {StereoLayout::sbs, false, DetectionRule::aspect, {}};
    if (aspect_says_full_top_bottom(aspect)) return {StereoLayout::tab, false, DetectionRule::aspect, {}};
    return {StereoLayout::mono, false, DetectionRule::fallback,
            fmt::format("no stereo layout detected for {} ({}x{}); showing it as 2D to both eyes (pass --layout "
                        "to choose one)",
                        evidence.filename.filename().string(), w, h)};
  }();
  // JPS stores the right view on the left by definition of the format, whatever decided the layout.
  if (is_jps(evidence.filename)) decision.swap_eyes = !decision.swap_eyes;
  // --swap-eyes swaps on top of whatever was detected.
  if (evidence.swap_eyes) decision.swap_eyes = !decision.swap_eyes;
  return decision;
}

}  // namespace nelf
