#include "compositor/gl/shader_programs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace nelf::shaders {

namespace {

std::string_view kind_name(ProgramKind kind) {
  switch (kind) {
    case ProgramKind::elemental:
      return "elemental";
    case ProgramKind::border:
      return "border";
    case ProgramKind::map:
      return "map";
    case ProgramKind::record:
      return "record";
    case ProgramKind::lookup:
      return "lookup";
    case ProgramKind::reduce:
      return "reduce";
    case ProgramKind::box:
      return "box";
    case ProgramKind::text_overlay:
      return "text_overlay";
    case ProgramKind::depth:
      return "depth";
    case ProgramKind::depth_border:
      return "depth_border";
    case ProgramKind::depth_map:
      return "depth_map";
    case ProgramKind::depth_lookup:
      return "depth_lookup";
    case ProgramKind::depth_border_hits:
      return "depth_border_hits";
    case ProgramKind::depth_record:
      return "depth_record";
    case ProgramKind::defect_gather:
      return "defect_gather";
    case ProgramKind::defect_apply:
      return "defect_apply";
  }
  return "unknown";
}

bool takes_subsamples(ProgramKind kind) {
  return kind == ProgramKind::elemental || kind == ProgramKind::border || kind == ProgramKind::depth ||
         kind == ProgramKind::depth_border;
}

}  // namespace

ProgramSource program_source(ProgramKind kind, int subsamples) {
  if (std::find(subsample_counts.begin(), subsample_counts.end(), subsamples) == subsample_counts.end())
    throw std::invalid_argument(fmt::format("program_source: {} sub-samples per axis (1, 2 or 4)", subsamples));
  const std::string per_axis = fmt::format("#define NELF_SUBSAMPLES {}\n", subsamples);
  switch (kind) {
    case ProgramKind::elemental:
      return {"fullscreen.vert", "elemental.frag", per_axis};
    case ProgramKind::border:
      return {"border_strips.vert", "elemental.frag", per_axis + "#define NELF_AREA_SAMPLE 1\n"};
    // One sample per pixel: both exist only for fsaa 1.
    case ProgramKind::map:
      return {"fullscreen.vert", "elemental.frag", "#define NELF_COORDINATE_MAP 1\n"};
    case ProgramKind::record:
      return {"border_strips.vert", "elemental.frag", "#define NELF_AREA_SAMPLE 1\n#define NELF_RECORD_TAPS 1\n"};
    case ProgramKind::lookup:
      return {"fullscreen.vert", "elemental_lookup.frag", {}};
    case ProgramKind::reduce:
      return {"fullscreen.vert", "prefilter_reduce.frag", {}};
    case ProgramKind::box:
      return {"fullscreen.vert", "prefilter_box.frag", {}};
    case ProgramKind::text_overlay:
      return {"fullscreen.vert", "text_overlay.frag", {}};
    case ProgramKind::depth:
      return {"fullscreen.vert", "elemental.frag", per_axis + "#define NELF_DEPTH 1\n"};
    case ProgramKind::depth_border:
      return {"border_strips.vert", "elemental.frag", per_axis + "#define NELF_AREA_SAMPLE 1\n#define NELF_DEPTH 1\n"};
    // One sample per pixel: both exist only for fsaa 1.
    case ProgramKind::depth_map:
      return {"fullscreen.vert", "elemental.frag", "#define NELF_DEPTH_MAP 1\n"};
    case ProgramKind::depth_lookup:
      return {"fullscreen.vert", "elemental_depth_lookup.frag", {}};
    case ProgramKind::depth_border_hits:
      return {"border_strips.vert", "elemental.frag", "#define NELF_AREA_SAMPLE 1\n#define NELF_DEPTH_HITS 1\n"};
    case ProgramKind::depth_record:
      return {"border_strips.vert", "elemental.frag",
              "#define NELF_AREA_SAMPLE 1\n#define NELF_DEPTH_HITS 1\n#define NELF_RECORD_TAPS 1\n"};
    case ProgramKind::defect_gather:
      return {"defect_gather.vert", "defect_gather.frag", {}};
    case ProgramKind::defect_apply:
      return {"defect_apply.vert", "defect_apply.frag", {}};
  }
  throw std::invalid_argument("program_source: unknown program kind");
}

std::vector<ProgramVariant> every_program_variant() {
  std::vector<ProgramVariant> variants;
  for (ProgramKind kind : every_program_kind) {
    if (!takes_subsamples(kind)) {
      variants.push_back({std::string(kind_name(kind)), program_source(kind, 1)});
      continue;
    }
    for (int subsamples : subsample_counts)
      variants.push_back({fmt::format("{}_x{}", kind_name(kind), subsamples), program_source(kind, subsamples)});
  }
  return variants;
}

}  // namespace nelf::shaders
