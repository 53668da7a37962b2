// Fuzz target: stereo layout detection (inputs/stereo_layout.*): release-name tokens, the detection
// order over arbitrary evidence (flag, metadata, frame size, display aspect, file name) and the
// regions a layout cuts out of a frame. The front of the input is the file name (so that the
// dictionary's tokens land in it), the back feeds the numbers.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "inputs/stereo_layout.hpp"
#include "inputs/view_regions.hpp"

namespace {

void require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "broken invariant: %s\n", what);
    std::abort();
  }
}

bool inside(const nelf::PixelRect& r, int width, int height) {
  return r.x >= 0 && r.y >= 0 && r.width > 0 && r.height > 0 && r.x + r.width <= width && r.y + r.height <= height;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const std::string name = in.ConsumeRandomLengthString(512);
  constexpr int kLayouts = 8, kPackings = 8;

  nelf::LayoutEvidence evidence;
  if (in.ConsumeBool()) evidence.flag = static_cast<nelf::StereoLayout>(in.ConsumeIntegralInRange(0, kLayouts - 1));
  if (in.ConsumeBool())
    evidence.metadata = nelf::StereoMetadata{
        static_cast<nelf::StereoPacking>(in.ConsumeIntegralInRange(0, kPackings - 1)), in.ConsumeBool()};
  // Frame sizes as a decoder delivers them (never negative), up to well past the largest accepted.
  evidence.width = in.ConsumeIntegralInRange(0, 1 << 16);
  evidence.height = in.ConsumeIntegralInRange(0, 1 << 16);
  evidence.filename = name;
  evidence.swap_eyes = in.ConsumeBool();
  // A sample aspect ratio can be anything a file says: 0 (unknown), tiny, huge.
  evidence.display_aspect = in.ConsumeBool() ? in.ConsumeFloatingPointInRange(0.0, 1e6) : 0.0;

  (void)nelf::parse_stereo_layout(name);
  (void)nelf::frame_packed_geometry(evidence.width, evidence.height);
  if (const auto named = nelf::layout_from_filename(evidence.filename, evidence.display_aspect))
    require(nelf::parse_stereo_layout(nelf::to_string(named->layout)).has_value(), "a file name gives a named layout");

  nelf::LayoutDecision decision;
  try {
    decision = nelf::detect_stereo_layout(evidence);
  } catch (const nelf::UnsupportedStereoMetadata&) {
    require(evidence.metadata && !evidence.flag, "only metadata without a flag is unsupported");
    return 0;
  }
  require(decision.rule != nelf::DetectionRule::flag || decision.layout == *evidence.flag, "the flag wins");
  require(nelf::parse_stereo_layout(nelf::to_string(decision.layout)) == decision.layout, "layout names round-trip");

  try {
    const nelf::ViewRegions r = nelf::view_regions(decision.layout, evidence.width, evidence.height, decision.swap_eyes,
                                                   evidence.display_aspect);
    require(inside(r.left, evidence.width, evidence.height), "the left view lies in the frame");
    require(inside(r.right, evidence.width, evidence.height), "the right view lies in the frame");
    require(r.left.width == r.right.width && r.left.height == r.right.height, "both views have one size");
    require(std::isfinite(r.display_aspect) && r.display_aspect >= 0.0, "a view's display aspect is a number");
  } catch (const nelf::LayoutError&) {
  }

  // Splitting real pixels: small frames only (the regions above cover the large ones).
  const int w = evidence.width % 97, h = evidence.height % 97;
  try {
    const nelf::Image frame(w, h);
    const nelf::StereoPair pair = nelf::split_frame(frame, decision.layout, decision.swap_eyes);
    require(
        pair.left.image.width() == pair.right.image.width() && pair.left.image.height() == pair.right.image.height(),
        "split views have one size");
    require(!pair.left.image.empty(), "split views are not empty");
  } catch (const nelf::LayoutError&) {
  }
  return 0;
}
