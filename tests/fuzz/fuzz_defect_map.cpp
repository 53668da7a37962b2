// Fuzz target: a panel's defect map (optics/defect_map.*, `correction.defect_map`) and the
// compensation planned from it (optics/defect_compensation*). A defect map travels with a profile
// that someone shares, so its text is a stranger's. Byte 0 picks a built-in profile (its panel, and
// lenses or none); the rest is the map's text. A map is refused with DefectMapError (one line) or
// accepted; an accepted one must read back equal from defect_map_text (what `nelf calibrate` writes)
// and, when small enough to plan in a moment, give each eye a plan whose shares lie on healthy
// pixels of the panel with finite weights ≥ 0, and whose application on a grey panel leaves the
// defects' own pixels alone.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "optics/defect_compensation.hpp"
#include "optics/defect_map.hpp"
#include "optics/mapping.hpp"
#include "optics/profile.hpp"

namespace {

void require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "broken invariant: %s\n", what);
    std::abort();
  }
}

// Planning solves a small problem per defect (a few ms for a thousand on hmz-t1); more defects than
// this are still parsed and written back, but not planned, to keep the fuzzer's rate.
constexpr std::size_t kPlannedAtMost = 64;
constexpr std::uint8_t kGrey = 128;

const std::vector<nelf::Profile>& profiles() {
  static const std::vector<nelf::Profile> all = [] {
    std::vector<nelf::Profile> loaded;
    for (const auto& info : nelf::builtin_profiles()) loaded.push_back(nelf::load_profile(info.name));
    return loaded;
  }();
  return all;
}

// The plan for one eye, checked, then applied to an 8-bit RGBA panel that is grey wherever the plan
// can write (the buffer is kept between inputs: only the pixels touched are reset).
void check_eye(const nelf::Profile& profile, nelf::Eye eye, const nelf::DefectMap& map) {
  const nelf::EyeMapping mapping = nelf::make_eye_mapping(profile, eye, 16.0 / 9.0);
  const nelf::EyeDefectPlan plan = nelf::plan_defect_compensation(mapping, map);
  const std::array<int, 2> panel = profile.display.resolution;
  require(plan.eye == eye && plan.panel == panel, "the plan is for the eye and panel it was asked for");

  std::set<std::tuple<int, int>> defective;
  for (const auto& d : map.defects)
    if (d.eye == eye) defective.insert({d.x, d.y});
  require(plan.corrections.size() + static_cast<std::size_t>(plan.outside_lit + plan.uncompensable) <= defective.size(),
          "each of the eye's defects is corrected, outside the lit area, uncompensable or unseen, once");
  require(plan.outside_lit >= 0 && plan.uncompensable >= 0, "the counts are not negative");

  std::vector<std::array<int, 2>> touched;
  for (const auto& correction : plan.corrections) {
    require(correction.defect.eye == eye && defective.contains({correction.defect.x, correction.defect.y}),
            "a correction is for one of the eye's defects");
    require(!correction.shares.empty(), "a correction has shares");
    for (const auto& share : correction.shares) {
      require(share.x >= 0 && share.y >= 0 && share.x < panel[0] && share.y < panel[1], "a share is on the panel");
      require(std::isfinite(share.weight) && share.weight >= 0.f, "a share's weight is finite and not negative");
      require(!defective.contains({share.x, share.y}), "a share is on a healthy pixel");
      touched.push_back({share.x, share.y});
    }
  }
  for (const auto& d : map.defects)
    if (d.eye == eye) touched.push_back({d.x, d.y});

  static std::vector<std::uint8_t> rgba;
  const std::size_t row_bytes = static_cast<std::size_t>(panel[0]) * 4;
  if (rgba.size() < row_bytes * static_cast<std::size_t>(panel[1])) rgba.assign(row_bytes * panel[1], kGrey);
  nelf::compensate_defects(plan, rgba.data(), 8, row_bytes);
  for (const auto& d : map.defects) {
    if (d.eye != eye) continue;
    const std::uint8_t* p = rgba.data() + static_cast<std::size_t>(d.y) * row_bytes + static_cast<std::size_t>(d.x) * 4;
    require(p[0] == kGrey && p[1] == kGrey && p[2] == kGrey, "a defect's own pixel is left as it was sent");
  }
  for (const auto& [x, y] : touched) {
    std::uint8_t* p = rgba.data() + static_cast<std::size_t>(y) * row_bytes + static_cast<std::size_t>(x) * 4;
    p[0] = p[1] = p[2] = p[3] = kGrey;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const nelf::Profile& profile = profiles()[data[0] % profiles().size()];
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  nelf::DefectMap map;
  try {
    map = nelf::parse_defect_map(text, "fuzz.defects", profile.display.resolution);
  } catch (const nelf::DefectMapError&) {
    return 0;  // refused with a message: what most inputs must get
  }
  const std::string written = nelf::defect_map_text(map);
  try {
    require(nelf::parse_defect_map(written, "round trip", profile.display.resolution) == map,
            "defect_map_text reads back equal");
  } catch (const nelf::DefectMapError& e) {
    std::fprintf(stderr, "an accepted map is refused once written back: %s\n%s\n", e.what(), written.c_str());
    std::abort();
  }
  if (map.defects.size() > kPlannedAtMost) return 0;
  for (nelf::Eye eye : {nelf::Eye::left, nelf::Eye::right}) check_eye(profile, eye, map);
  return 0;
}
