#include "compositor/make_compositor.hpp"

#include "compositor/gl/gl_compositor.hpp"

namespace nelf {

std::unique_ptr<Compositor> make_compositor(const Profile& profile, const CompositorOptions& options) {
  validate_fsaa(options.fsaa);
  auto context = std::make_shared<gl::EglContext>(gl::ContextOptions{options.gpu});
  return std::make_unique<GlCompositor>(profile, options, std::move(context));
}

}  // namespace nelf
