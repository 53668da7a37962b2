#pragma once
// A source whose frames carry the content's depth estimated from their two views (issue #15's
// `estimated` depth source, inputs/stereo_matcher): what `--depth estimate`, and `--depth auto` for
// inputs that know no depth of their own, put in front of any source. A frame the matcher cannot
// match (flat, black, no texture) goes on without depth: the compositor shows it on the flat screen.
#include <memory>

#include "inputs/source.hpp"
#include "inputs/stereo_matcher.hpp"

namespace nelf {

// `source` with each frame's disparity estimated; `keep_known`: frames that already carry one (a
// synthetic scene's exact depth) keep it. The matcher's temporal filter restarts after a seek.
std::unique_ptr<Source> with_estimated_depth(std::unique_ptr<Source> source, bool keep_known,
                                             StereoMatcherSettings settings = {});

}  // namespace nelf
