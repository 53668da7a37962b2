// The video path's per-frame compositing cost, GL against the CPU composite table (DESIGN.md §10):
// hmz-t1, both eyes from the block means of two 960×1080 half side-by-side views (what nelf convert
// and nelf play hand the compositor) into a 1280×1470 packed RGBA8 frame in memory.
//   gl      upload both block-mean textures, render_eye_reduced per eye, glReadPixels (convert's GL path);
//   table   CompositeTable::render per eye straight into the packed frame (convert's CPU path).
// With `depth` as the second argument, both depth-aware (the table recorded with its rays, GL's
// depth pass), for a 240×135 disparity map of gentle hills in front of the screen and a block at
// 250 mm over a sixth of the view.
// Not a test: run by hand, results go to docs/PERFORMANCE.md. Runs are interleaved; the first of
// each is dropped; medians.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bench/bench_timing.hpp"
#include "compositor/gl/gl_compositor.hpp"
#include "optics/depth.hpp"

namespace {

using nelf::bench::elapsed_ms;
using nelf::bench::median;

}  // namespace

int main(int argc, char** argv) {
  try {
    const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 21;
    auto context = std::make_shared<nelf::gl::EglContext>();
    const nelf::Profile profile = nelf::load_profile("hmz-t1");
    const bool depth = argc > 2 && std::string(argv[2]) == "depth";
    const nelf::CompositorOptions options{1, std::nullopt, depth ? nelf::DepthMode::automatic : nelf::DepthMode::off};
    const int view_w = 960, view_h = 1080;
    const double aspect = 16.0 / 9.0;
    const auto block = nelf::stereo_prefilter_block(profile, options, view_w, view_h, aspect);
    const int mw = view_w / block[0], mh = view_h / block[1];
    std::vector<std::uint8_t> means(static_cast<std::size_t>(mw) * mh * 4);
    for (int y = 0; y < mh; ++y)
      for (int x = 0; x < mw; ++x) {
        const double u = x / double(mw), t = y / double(mh);
        std::uint8_t* p = &means[(static_cast<std::size_t>(y) * mw + x) * 4];
        p[0] = static_cast<std::uint8_t>(127.5 + 127.5 * std::sin(40 * u * u + 23 * t));
        p[1] = static_cast<std::uint8_t>(255 * u), p[2] = static_cast<std::uint8_t>(255 * t), p[3] = 255;
      }
    nelf::GlCompositor compositor(profile, options, context);
    const auto panel = compositor.panel();
    const int packed_w = panel[0], packed_h = 2 * panel[1] + 30;
    std::vector<std::uint8_t> packed(static_cast<std::size_t>(packed_w) * packed_h * 4);
    const nelf::gl::Texture views[2] = {nelf::gl::make_texture_2d(GL_RGBA8, mw, mh),
                                        nelf::gl::make_texture_2d(GL_RGBA8, mw, mh)};
    const nelf::gl::Texture target_texture = nelf::gl::make_texture_2d(GL_RGBA8, packed_w, packed_h);
    const nelf::gl::Framebuffer target = nelf::gl::make_framebuffer(target_texture);
    std::shared_ptr<const nelf::DisparitySurface> surface;
    if (depth) {
      const nelf::EyeMapping m = nelf::make_eye_mapping(profile, nelf::Eye::left, aspect);
      const nelf::DepthGeometry g = nelf::depth_geometry(profile, m);
      const int w = 240, h = 135;
      const float near_px = static_cast<float>(nelf::disparity_mm_from_depth(g, 250.0) / g.screen_size_mm.x * w);
      nelf::ViewDisparity d{w, h, std::vector<float>(static_cast<std::size_t>(w) * h)};
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          d.d[static_cast<std::size_t>(y) * w + x] =
              x > w / 6 && x < w / 3 && y > h / 4 && y < h / 2
                  ? near_px
                  : 0.15f * near_px * static_cast<float>(1.0 + std::sin(0.09 * x) * std::cos(0.13 * y));
      surface = std::make_shared<const nelf::DisparitySurface>(d);
      for (nelf::Eye eye : {nelf::Eye::left, nelf::Eye::right}) compositor.set_depth(eye, surface);
    }
    auto left = compositor.make_composite_table(nelf::Eye::left, view_w, view_h, aspect, block);
    auto right = compositor.make_composite_table(nelf::Eye::right, view_w, view_h, aspect, block);
    if (!left || !right) throw std::runtime_error("no composite table for hmz-t1");

    std::printf("renderer: %s, %d runs, hmz-t1, 2 x %dx%d views as %dx%d block means, packed %dx%d%s\n",
                context->renderer().c_str(), runs, view_w, view_h, mw, mh, packed_w, packed_h,
                depth ? ", depth-aware" : "");
    std::vector<double> gl_ms, table_ms;
    const std::size_t stride = static_cast<std::size_t>(packed_w) * 4;
    for (int run = 0; run <= runs; ++run) {
      const double gl = elapsed_ms([&] {
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        for (const auto& v : views)
          glTextureSubImage2D(v.id(), 0, 0, 0, mw, mh, GL_RGBA, GL_UNSIGNED_BYTE, means.data());
        compositor.render_eye_reduced(nelf::Eye::left, {{views[0].id(), view_w, view_h, aspect}, block},
                                      {target.id(), 0, 0});
        compositor.render_eye_reduced(nelf::Eye::right, {{views[1].id(), view_w, view_h, aspect}, block},
                                      {target.id(), 0, panel[1] + 30});
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, packed_w, packed_h, GL_RGBA, GL_UNSIGNED_BYTE, packed.data());
      });
      const double table = elapsed_ms([&] {
        left->render(means.data(), static_cast<std::size_t>(mw) * 4, packed.data(), stride, nelf::ChannelOrder::rgba,
                     surface.get());
        right->render(means.data(), static_cast<std::size_t>(mw) * 4, packed.data() + (panel[1] + 30) * stride, stride,
                      nelf::ChannelOrder::rgba, surface.get());
      });
      if (run > 0) gl_ms.push_back(gl), table_ms.push_back(table);
    }
    const double g = median(gl_ms), t = median(table_ms);
    std::printf("gl     %8.2f ms per frame (render_eye_reduced x2 + read-back)\n", g);
    std::printf("table  %8.2f ms per frame (CompositeTable::render x2)\n", t);
    std::printf("ratio  %8.2f (gl / table)\n", g / t);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "composite_table_bench: %s\n", e.what());
    return 1;
  }
}
