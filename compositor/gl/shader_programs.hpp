#pragma once
// Every GL program the compositor compiles: its two stages and their defines. GlCompositor and the
// text overlay build their programs from this table, and the build writes out and validates each
// entry with glslangValidator (cmake/write_shader_variants.cpp), so no variant reaches a driver
// unchecked.
#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace nelf::shaders {

enum class ProgramKind {
  elemental,          // pass 1: point samples of the mapping, every pixel
  border,             // pass 2: area samples along the elemental-image borders
  map,                // pass 1's coordinate map (fsaa 1)
  record,             // the border strips' taps, written down for the CPU composite table
  lookup,             // pass 1 from the coordinate map: one tap per pixel
  reduce,             // footprint prefilter, step 1: block means
  box,                // footprint prefilter, step 2: one box per axis
  text_overlay,       // labels drawn into the packed frame
  depth,              // pass 1 of the depth-aware composite: point samples where each ray meets the content
  depth_border,       // its pass 2: area samples along the borders, each part where its ray meets the content
  depth_map,          // its pass 1's depth coordinate map (fsaa 1): each pixel's flat-screen point and pupil crossing
  depth_lookup,       // its pass 1 from the depth coordinate map: the search and one tap per pixel
  depth_border_hits,  // its border strips after depth_lookup: each part takes a crossing pass 1 found
  depth_record,       // those strips' rays and borrowed crossings, written down for the CPU depth-aware table
  defect_gather,      // defect compensation, pass 1: what each defect was sent, less what it shows
  defect_apply,       // its pass 2: each pixel's shares added to the frame
};
inline constexpr std::array every_program_kind = {
    ProgramKind::elemental,
    ProgramKind::border,
    ProgramKind::map,
    ProgramKind::record,
    ProgramKind::lookup,
    ProgramKind::reduce,
    ProgramKind::box,
    ProgramKind::text_overlay,
    ProgramKind::depth,
    ProgramKind::depth_border,
    ProgramKind::depth_map,
    ProgramKind::depth_lookup,
    ProgramKind::depth_border_hits,
    ProgramKind::depth_record,
    ProgramKind::defect_gather,
    ProgramKind::defect_apply,
};

struct ProgramSource {
  std::string_view vertex;  // embedded file name, shaders/
  std::string_view fragment;
  std::string defines;  // "#define ...\n" lines, inserted after #version
};

// Sub-samples per axis the mapping programs are compiled for (fsaa 0/1, 4, 16).
inline constexpr std::array subsample_counts = {1, 2, 4};

// The program `kind` for `subsamples` per axis (1, 2 or 4; only the elemental and border passes
// take it, the others ignore it).
ProgramSource program_source(ProgramKind kind, int subsamples);

struct ProgramVariant {
  std::string name;  // e.g. "border_x2": unique, usable as a file name
  ProgramSource source;
};
// Each distinct program that program_source can return.
std::vector<ProgramVariant> every_program_variant();

}  // namespace nelf::shaders
