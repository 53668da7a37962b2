#pragma once
// The one place that picks the Compositor implementation, so that commands never depend on which.
#include <memory>

#include "compositor/compositor.hpp"
#include "optics/profile.hpp"

namespace nelf {

// A compositor for `profile` with `options` (options.fsaa must have passed validate_fsaa).
std::unique_ptr<Compositor> make_compositor(const Profile& profile, const CompositorOptions& options);

}  // namespace nelf
