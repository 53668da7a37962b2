// Compositor cost per frame pair at each fsaa level (DESIGN.md §10): hmz-t1, two 1920×1080 views.
// Not a test: run by hand, results go to docs/PERFORMANCE.md. Two figures per level:
//   render    both eyes from textures already on the GPU into an FBO (the video path);
//   compose   GlCompositor::compose(): upload both float views, render, read both eyes back.
// Each is the median of several runs after a warm-up run, timed up to glFinish. The last rows are
// the depth-aware pass (fsaa 1 with a disparity surface: a plane in front of a background behind
// the screen) from a 480×270 map and from a 960×540 one (the stereo estimator's size, whose rays
// cross twice the texels), their ratios against fsaa 1 (issue #15 asks ≤ 1.5×).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "bench/bench_timing.hpp"
#include "compositor/gl/gl_compositor.hpp"
#include "optics/depth.hpp"

namespace {

using nelf::bench::elapsed_ms;
using nelf::bench::median;

nelf::Image test_view(int width, int height) {
  nelf::Image image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double u = x / double(width), t = y / double(height);
      const float v = static_cast<float>(0.5 + 0.5 * std::sin(2 * std::numbers::pi * (30 * u * u + 17 * t)));
      image.at(x, y) = {v, static_cast<float>(u), static_cast<float>(t), 1.f};
    }
  return image;
}

// Disparity of a 480k×270k map (view pixels of the map): a centred plane 12k px in front of a
// background 4k px behind the screen (48 and 16 px of a 1920-wide view).
nelf::ViewDisparity plane_in_front(int k) {
  const int width = 480 * k, height = 270 * k;
  nelf::ViewDisparity d{width, height, std::vector<float>(static_cast<std::size_t>(width) * height, -4.f * k)};
  for (int y = 90 * k; y < 180 * k; ++y)
    for (int x = 160 * k; x < 320 * k; ++x) d.d[static_cast<std::size_t>(y) * width + x] = 12.f * k;
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 9;
    auto context = std::make_shared<nelf::gl::EglContext>();
    const nelf::Profile profile = nelf::load_profile("hmz-t1");
    const nelf::StereoPair views{{test_view(1920, 1080), 0.0}, {test_view(1920, 1080), 0.0}};
    // The video path's views: 8-bit textures as decoded frames arrive (argument 2: "16f" or "32f").
    const std::string format_name = argc > 2 ? argv[2] : "8";
    const GLenum format = format_name == "32f" ? GL_RGBA32F : format_name == "16f" ? GL_RGBA16F : GL_RGBA8;
    const nelf::gl::Texture left = nelf::upload_texture(views.left.image, format);
    const nelf::gl::Texture right = nelf::upload_texture(views.right.image, format);
    const auto panel = profile.display.resolution;
    const nelf::gl::Texture target_texture = nelf::gl::make_texture_2d(GL_RGBA8, panel[0], 2 * panel[1]);
    const nelf::gl::Framebuffer target = nelf::gl::make_framebuffer(target_texture);

    std::printf("renderer: %s (%s), %d runs per figure, hmz-t1, 2 x 1920x1080 views, render from RGBA%s\n",
                context->renderer().c_str(), context->device().c_str(), runs, format_name.c_str());
    std::printf("%-6s %12s %8s %14s %8s\n", "fsaa", "render ms", "ratio", "compose ms", "ratio");
    // The levels are interleaved run by run, so load from other processes on a shared machine
    // hits all of them alike; the first run of each (shader compilation, allocation) is dropped.
    const int levels[] = {0, 1, 4, 16, 1, 1};
    const std::size_t depth_level = 4;  // and 5
    std::vector<std::unique_ptr<nelf::GlCompositor>> compositors;
    for (int fsaa : levels)
      compositors.push_back(
          std::make_unique<nelf::GlCompositor>(profile, nelf::CompositorOptions{fsaa, std::nullopt}, context));
    for (int k : {1, 2}) {
      const auto surface = std::make_shared<const nelf::DisparitySurface>(plane_in_front(k));
      for (nelf::Eye eye : {nelf::Eye::left, nelf::Eye::right})
        compositors[depth_level + k - 1]->set_depth(eye, surface);
    }
    std::vector<std::vector<double>> render_ms(std::size(levels)), compose_ms(std::size(levels));
    for (int run = 0; run <= runs; ++run) {
      for (std::size_t level = 0; level < compositors.size(); ++level) {
        nelf::GlCompositor& compositor = *compositors[level];
        const double render = elapsed_ms([&] {
          compositor.render_eye(nelf::Eye::left, {left.id(), 1920, 1080, 0.0}, {target.id(), 0, 0});
          compositor.render_eye(nelf::Eye::right, {right.id(), 1920, 1080, 0.0}, {target.id(), 0, panel[1]});
          glFinish();
        });
        const double compose = elapsed_ms([&] {
          compositor.compose(views);
          glFinish();
        });
        if (run > 0) render_ms[level].push_back(render), compose_ms[level].push_back(compose);
      }
    }
    const double render_base = median(render_ms[0]), compose_base = median(compose_ms[0]);
    for (std::size_t level = 0; level < depth_level; ++level) {
      const double render = median(render_ms[level]), compose = median(compose_ms[level]);
      std::printf("%-6d %12.1f %8.2f %14.1f %8.2f\n", levels[level], render, render / render_base, compose,
                  compose / compose_base);
    }
    for (int k : {1, 2}) {
      const std::size_t level = depth_level + k - 1;
      const double depth_render = median(render_ms[level]), depth_compose = median(compose_ms[level]);
      std::printf("%-6s %12.1f %8.2f %14.1f %8.2f  (ratios against fsaa 1; a %dx%d map)\n", k == 1 ? "1+dep" : "1+dep2",
                  depth_render, depth_render / median(render_ms[1]), depth_compose,
                  depth_compose / median(compose_ms[1]), 480 * k, 270 * k);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "compositor_bench: %s\n", e.what());
    return 1;
  }
}
