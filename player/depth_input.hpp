#pragma once
// The input a `--depth` mode needs (issue #15), for play and convert alike.
#include <memory>

#include "compositor/compositor.hpp"
#include "inputs/source.hpp"
#include "optics/profile.hpp"

namespace nelf {

// Opens `request` for `mode` on `display`: off, the input as it is; auto, a synthetic scene filmed
// for the display with its exact depth on every frame, any other input's depth estimated from its
// two views; estimate, every input's depth estimated (a synthetic scene still filmed for the
// display, so that the estimate can be judged against its real depth). A display without a lens
// array cannot show depth: the input as it is (the compositor says so once).
std::unique_ptr<Source> open_source_for_depth(SourceRequest request, DepthMode mode, const Profile& display);

}  // namespace nelf
