#include "compositor/make_compositor.hpp"

#include "compositor/reference.hpp"

namespace nelf {

std::unique_ptr<Compositor> make_compositor(const Profile& profile, const CompositorOptions& options) {
  validate_fsaa(options.fsaa);
  // Until the GL compositor is integrated, the CPU reference does the work, at 4x4 sub-samples per
  // pixel: a few seconds per still instead of minutes at the reference's 16x16. On integration this
  // returns the GL compositor (which honours options.fsaa); callers do not change.
  return std::make_unique<ReferenceCompositor>(profile, 4);
}

}  // namespace nelf
