// The compositor facade (compositor/frame_compositor.hpp) on llvmpipe: its two paths (GL and the
// CPU composite tables) agree, the eyes land where the packed layout says, the overlays do what
// they should, a profile that fails keeps the old one, frames come composited ahead into a GL
// target, and stills are what convert wrote before the facade.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include "compositor/frame_compositor.hpp"
#include "compositor/gl/gl_compositor.hpp"
#include "hmz_output/packing.hpp"
#include "hmz_output/signal.hpp"
#include "support/gl_test_support.hpp"

namespace nelf {
namespace {
// This file's own names: its suite is compiled as one unit (tests/CMakeLists.txt).
namespace test_frame_compositor {

using test::block_means;
using Bytes = std::vector<std::uint8_t>;

// NELF_COMPOSITE for the scope: "gl" or "table" picks the path, whatever the renderer.
class CompositeEnvironment {
 public:
  explicit CompositeEnvironment(const char* choice) { ::setenv("NELF_COMPOSITE", choice, 1); }
  ~CompositeEnvironment() { ::unsetenv("NELF_COMPOSITE"); }
};

constexpr int kViewW = 480, kViewH = 272;

PackedLayout layout_for(const Profile& profile, const char* signal) {
  return packed_layout(*find_signal(signal), profile.display.resolution);
}

// A stereo frame of block means as the compositor wants them: a photo chart left, a zone plate right.
FrameCompositor::Frame test_frame(const FrameCompositor& compositor, bool exchanged = false) {
  auto frame = std::make_shared<StereoVideoFrame>();
  frame->width = kViewW;
  frame->height = kViewH;
  frame->block = compositor.wanted_block(kViewW, kViewH, 0.0);
  frame->left = block_means(test::photo_chart(kViewW, kViewH), frame->block);
  frame->right = block_means(test::zone_plate(kViewW, kViewH), frame->block);
  if (exchanged) std::swap(frame->left, frame->right);
  frame->pts_s = 1.5;
  return frame;
}

PackedFrame render_bytes(FrameCompositor& compositor, const FrameCompositor::Frame& frame,
                         const FrameOverlays& overlays = {}) {
  PackedFrame out;
  EXPECT_FALSE(compositor.render(frame, overlays, PackedTarget::bytes(out)));
  return out;
}

struct Difference {
  int max = 0;
  double mean = 0.0;
};
Difference difference(const Bytes& a, const Bytes& b) {
  EXPECT_EQ(a.size(), b.size());
  Difference d;
  long long total = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    const int v = std::abs(a[i] - b[i]);
    d.max = std::max(d.max, v);
    total += v;
  }
  d.mean = a.empty() ? 0.0 : static_cast<double>(total) / a.size();
  return d;
}

bool inside_an_eye(const PackedLayout& layout, int x, int y) {
  for (const auto& origin : layout.origins)
    if (origin && x >= origin->first && x < origin->first + layout.eye[0] && y >= origin->second &&
        y < origin->second + layout.eye[1])
      return true;
  return false;
}

// Opaque black outside the eyes; a picture inside each.
void expect_eyes_at_the_origins(const PackedFrame& frame, const PackedLayout& layout) {
  ASSERT_EQ(frame.width, layout.packed[0]);
  ASSERT_EQ(frame.height, layout.packed[1]);
  ASSERT_EQ(frame.rgba.size(), static_cast<std::size_t>(frame.width) * frame.height * 4);
  long long outside_wrong = 0;
  std::array<long long, 2> lit{0, 0};
  for (int y = 0; y < frame.height; ++y)
    for (int x = 0; x < frame.width; ++x) {
      const std::uint8_t* p = &frame.rgba[(static_cast<std::size_t>(y) * frame.width + x) * 4];
      if (!inside_an_eye(layout, x, y)) {
        outside_wrong += p[0] != 0 || p[1] != 0 || p[2] != 0 || p[3] != 255;
        continue;
      }
      for (int e = 0; e < 2; ++e) {
        const auto& o = layout.origins[e];
        if (o && x >= o->first && x < o->first + layout.eye[0] && y >= o->second && y < o->second + layout.eye[1])
          lit[e] += p[0] + p[1] + p[2];
      }
    }
  EXPECT_EQ(outside_wrong, 0);
  const double eye_pixels = static_cast<double>(layout.eye[0]) * layout.eye[1] * 3;
  for (int e = 0; e < 2; ++e)
    if (layout.origins[e]) {
      EXPECT_GT(lit[e] / eye_pixels, 20.0) << "eye " << e;
    }
}

TEST(FrameCompositor, WantedBlocksAreThePrefiltersBlocks) {
  const Profile profile = test::small_panel_profile();
  const CompositorOptions options{1, std::nullopt};
  FrameCompositor compositor(profile, options, layout_for(profile, "sbs"));
  for (Eye eye : {Eye::left, Eye::right})
    EXPECT_EQ(compositor.wanted_block(eye, kViewW, kViewH, 16.0 / 9.0),
              prefilter_block(profile, options, eye, kViewW, kViewH, 16.0 / 9.0));
  EXPECT_EQ(compositor.wanted_block(kViewW, kViewH, 0.0),
            stereo_prefilter_block(profile, options, kViewW, kViewH, 0.0));
  EXPECT_NE(compositor.wanted_block(kViewW, kViewH, 0.0), (std::array<int, 2>{1, 1}));
  FrameCompositor whole(profile, {0, std::nullopt}, layout_for(profile, "sbs"));
  EXPECT_EQ(whole.wanted_block(kViewW, kViewH, 0.0), (std::array<int, 2>{1, 1}));
}

TEST(FrameCompositor, RefusesALayoutForAnotherPanel) {
  const Profile profile = test::small_panel_profile();
  EXPECT_THROW(FrameCompositor(profile, {}, packed_layout(*find_signal("sbs"), {640, 360})), std::invalid_argument);
  EXPECT_THROW(FrameCompositor(profile, {3, std::nullopt}, layout_for(profile, "sbs")), std::invalid_argument);
}

TEST(FrameCompositor, TablesAndGlGiveTheSamePackedFrameWithTheEyesAtTheLayoutsOrigins) {
  const Profile profile = test::small_panel_profile();
  for (const char* signal : {"hdmi-fp-720p60", "sbs", "right"}) {
    SCOPED_TRACE(signal);
    const PackedLayout layout = layout_for(profile, signal);
    PackedFrame from_gl, from_tables;
    {
      CompositeEnvironment gl("gl");
      FrameCompositor compositor(profile, {1, std::nullopt}, layout, test::shared_gl_context());
      from_gl = render_bytes(compositor, test_frame(compositor));
    }
    {
      CompositeEnvironment table("table");
      FrameCompositor compositor(profile, {1, std::nullopt}, layout, test::shared_gl_context());
      from_tables = render_bytes(compositor, test_frame(compositor));
    }
    for (const PackedFrame* frame : {&from_gl, &from_tables}) {
      EXPECT_EQ(frame->bits, 8);
      EXPECT_EQ(frame->pts_seconds, 1.5);
      expect_eyes_at_the_origins(*frame, layout);
    }
    // As tests/gl/test_composite_table.cpp holds the table against GL.
    const Difference d = difference(from_gl.rgba, from_tables.rgba);
    EXPECT_LE(d.max, 3);
    EXPECT_LT(d.mean, 0.1);
  }
}

TEST(FrameCompositor, WithoutAContextTheTablesComeFromTheCache) {
  // A compositor that records the tables leaves them in the cache; the next one for the same
  // optics and views composites from the cache alone, as a conversion does.
  CompositeEnvironment table("table");
  const Profile profile = test::small_panel_profile();
  const PackedLayout layout = layout_for(profile, "tab");
  PackedFrame recorded, cached;
  {
    FrameCompositor compositor(profile, {1, std::nullopt}, layout, test::shared_gl_context());
    recorded = render_bytes(compositor, test_frame(compositor));
  }
  {
    FrameCompositor compositor(profile, {1, std::nullopt}, layout);
    const auto frame = test_frame(compositor);
    compositor.prepare_views({frame->width, frame->height, frame->bits, frame->aspect, frame->block});
    cached = render_bytes(compositor, frame);
  }
  EXPECT_EQ(recorded.rgba, cached.rgba);
  expect_eyes_at_the_origins(cached, layout);
}

TEST(FrameCompositor, ConversionsTakeTheTablesForWholeViewsTooLiveOutputsOnlyForBlockMeans) {
  const Profile profile = test::small_panel_profile();
  const CompositorOptions options{1, std::nullopt};
  // Views small enough that the prefilter averages no block, yet filters: a table applies.
  GlCompositor recorder(profile, options, test::shared_gl_context());
  int w = 0, h = 0;
  for (int width = 96; width <= 480 && w == 0; width += 16) {
    const int height = width * 9 / 16;
    if (prefilter_block(profile, options, Eye::left, width, height, 0.0) == std::array<int, 2>{1, 1} &&
        prefilter_block(profile, options, Eye::right, width, height, 0.0) == std::array<int, 2>{1, 1} &&
        recorder.make_composite_table(Eye::left, width, height, 0.0, {1, 1}))
      w = width, h = height;
  }
  ASSERT_GT(w, 0);
  auto frame = std::make_shared<StereoVideoFrame>();
  frame->width = w;
  frame->height = h;
  frame->left = block_means(test::photo_chart(w, h), {1, 1});
  frame->right = block_means(test::zone_plate(w, h), {1, 1});
  const PackedLayout layout = layout_for(profile, "sbs");
  PackedFrame from_gl, live, conversion;
  {
    CompositeEnvironment gl("gl");
    FrameCompositor compositor(profile, options, layout, test::shared_gl_context());
    from_gl = render_bytes(compositor, frame);
  }
  {
    CompositeEnvironment table("table");
    FrameCompositor block_means_only(profile, options, layout, test::shared_gl_context(), TableUse::block_means);
    live = render_bytes(block_means_only, frame);
    FrameCompositor any_views(profile, options, layout, test::shared_gl_context(), TableUse::any_views);
    conversion = render_bytes(any_views, frame);
  }
  EXPECT_EQ(live.rgba, from_gl.rgba);  // GL drew it
  const Difference d = difference(conversion.rgba, from_gl.rgba);
  EXPECT_LE(d.max, 3);
  EXPECT_LT(d.mean, 0.1);
  expect_eyes_at_the_origins(conversion, layout);
}

TEST(FrameCompositor, SixteenBitViewsGiveASixteenBitFrame) {
  const Profile profile = test::small_panel_profile();
  const PackedLayout layout = layout_for(profile, "sbs");
  FrameCompositor compositor(profile, {1, std::nullopt}, layout, test::shared_gl_context());
  const auto eight = test_frame(compositor);
  auto sixteen = std::make_shared<StereoVideoFrame>(*eight);
  sixteen->bits = 16;
  for (auto* view : {&sixteen->left, &sixteen->right}) {
    Bytes wide(view->size() * 2);
    for (std::size_t i = 0; i < view->size(); ++i) {
      const std::uint16_t v = static_cast<std::uint16_t>((*view)[i] * 257);
      std::memcpy(&wide[i * 2], &v, 2);
    }
    *view = std::move(wide);
  }
  const PackedFrame out = render_bytes(compositor, sixteen);
  EXPECT_EQ(out.bits, 16);
  ASSERT_EQ(out.rgba.size(), static_cast<std::size_t>(layout.packed[0]) * layout.packed[1] * 8);
  // Its top bytes are the 8-bit frame's, within the paths' tolerance.
  const PackedFrame narrow = render_bytes(compositor, eight);
  Bytes high(narrow.rgba.size());
  for (std::size_t i = 0; i < high.size(); ++i) {
    std::uint16_t v;
    std::memcpy(&v, &out.rgba[i * 2], 2);
    high[i] = static_cast<std::uint8_t>(std::lround(v / 257.0));
  }
  EXPECT_LE(difference(narrow.rgba, high).max, 3);
}

TEST(FrameCompositor, OverlaysChangeWhatTheyShould) {
  const Profile profile = test::small_panel_profile();
  const PackedLayout layout = layout_for(profile, "sbs");
  for (const char* choice : {"gl", "table"}) {
    SCOPED_TRACE(choice);
    CompositeEnvironment environment(choice);
    FrameCompositor compositor(profile, {1, std::nullopt}, layout, test::shared_gl_context());
    compositor.set_grid_pattern([](const Profile&, int width, int height) {
      // Stripes: a white column every 16 pixels, black elsewhere (black shows the view through).
      Image grid(width, height);
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; x += 16) grid.at(x, y) = Rgba{1, 1, 1, 1};
      return EyeImages{grid, grid};
    });
    const auto frame = test_frame(compositor);
    const PackedFrame plain = render_bytes(compositor, frame);

    // Swapped eyes: exactly the frame with its views exchanged.
    const PackedFrame swapped = render_bytes(compositor, frame, {"", false, true});
    EXPECT_EQ(swapped.rgba, render_bytes(compositor, test_frame(compositor, true)).rgba);
    EXPECT_NE(swapped.rgba, plain.rgba);

    // The message and the grid change the eyes, never what lies around them; off again, the frame
    // is as before.
    const PackedFrame message = render_bytes(compositor, frame, {"paused", false, false});
    const PackedFrame grid = render_bytes(compositor, frame, {"", true, false});
    for (const PackedFrame* changed : {&message, &grid}) {
      EXPECT_GT(difference(changed->rgba, plain.rgba).mean, 0.05);
      expect_eyes_at_the_origins(*changed, layout);
    }
    EXPECT_NE(message.rgba, grid.rgba);
    EXPECT_EQ(render_bytes(compositor, frame).rgba, plain.rgba);
  }
}

TEST(FrameCompositor, AGridAskedWithoutAPatternIsRefused) {
  const Profile profile = test::small_panel_profile();
  FrameCompositor compositor(profile, {1, std::nullopt}, layout_for(profile, "sbs"), test::shared_gl_context());
  EXPECT_THROW(compositor.prepare(test_frame(compositor), {"", true, false}), std::logic_error);
}

TEST(FrameCompositor, AProfileThatFailsKeepsTheOldOne) {
  const Profile profile = test::small_panel_profile();
  FrameCompositor compositor(profile, {1, std::nullopt}, layout_for(profile, "sbs"), test::shared_gl_context());
  const auto frame = test_frame(compositor);
  const PackedFrame before = render_bytes(compositor, frame);

  // No screen fits both eyes' fields of view at this IPD: the mapping for the views fails.
  Profile failing = profile;
  failing.screen.converge = true;
  failing.screen.width_mm = 0.0;
  failing.viewing.ipd_mm = 10000.0;
  EXPECT_THROW(compositor.set_profile(failing), std::exception);
  EXPECT_EQ(compositor.profile().viewing.ipd_mm, profile.viewing.ipd_mm);
  EXPECT_EQ(render_bytes(compositor, frame).rgba, before.rgba);

  Profile other_panel = profile;
  other_panel.display.resolution = {640, 360};
  EXPECT_THROW(compositor.set_profile(other_panel), std::invalid_argument);
  EXPECT_EQ(compositor.profile().display.resolution, profile.display.resolution);

  // A usable change takes effect.
  Profile wider = profile;
  wider.viewing.ipd_mm += 4.0;
  compositor.set_profile(wider);
  EXPECT_EQ(compositor.profile().viewing.ipd_mm, wider.viewing.ipd_mm);
  EXPECT_NE(render_bytes(compositor, frame).rgba, before.rgba);
}

TEST(FrameCompositor, FramesCompositedAheadIntoAGlTarget) {
  CompositeEnvironment table("table");
  const Profile profile = test::small_panel_profile();
  const PackedLayout layout = layout_for(profile, "hdmi-fp-720p60");
  FrameCompositor compositor(profile, {1, std::nullopt}, layout, test::shared_gl_context());
  const gl::Texture texture = gl::make_texture_2d(GL_RGBA8, layout.packed[0], layout.packed[1]);
  const gl::Framebuffer fbo = gl::make_framebuffer(texture);
  const GlPackedTarget target{fbo.id(), texture.id(), layout.packed};
  const auto read_rgba = [&] {
    Bytes rgba(static_cast<std::size_t>(layout.packed[0]) * layout.packed[1] * 4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo.id());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, layout.packed[0], layout.packed[1], GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    return rgba;
  };
  const FrameOverlays overlays{"", false, true};
  const auto first = test_frame(compositor), second = test_frame(compositor, true);
  // The first render makes the tables (on this thread); then the next frames are made ahead.
  EXPECT_FALSE(compositor.render(first, overlays, {target}));
  const Bytes shown_first = read_rgba();
  EXPECT_EQ(shown_first, render_bytes(compositor, first, overlays).rgba);
  const std::vector<FrameCompositor::Frame> next{second};
  compositor.composite_ahead(next, overlays, target);
  compositor.wait_for_ahead(std::chrono::milliseconds(5000));
  EXPECT_TRUE(compositor.render(second, overlays, {target}));
  EXPECT_EQ(read_rgba(), render_bytes(compositor, second, overlays).rgba);
  // Made for other overlays: not shown, composited again.
  compositor.composite_ahead(std::vector<FrameCompositor::Frame>{first}, overlays, target);
  compositor.wait_for_ahead(std::chrono::milliseconds(5000));
  EXPECT_FALSE(compositor.render(first, {}, {target}));
  EXPECT_EQ(read_rgba(), render_bytes(compositor, first).rgba);
}

// test_frame() with depth: a block at 250 mm over the left third of both views, in pixels of a
// 240×136 map (the disparity a source attaches).
FrameCompositor::Frame depth_frame(const FrameCompositor& compositor, bool exchanged = false) {
  auto frame = std::make_shared<StereoVideoFrame>(*test_frame(compositor, exchanged));
  const int w = 240, h = 136;
  const auto surface = test::near_block_surface(compositor.profile(), double(kViewW) / kViewH, w, h);
  ViewDisparity map{w, h, std::vector<float>(static_cast<std::size_t>(w) * h)};
  for (std::size_t i = 0; i < map.d.size(); ++i) map.d[i] = surface->values()[i] * static_cast<float>(w);
  frame->disparity = std::make_shared<const StereoDisparity>(StereoDisparity{map, map, DisparityOrigin::estimated});
  return frame;
}

// Frames with depth take the tables too (their depth-aware rays) and agree with GL's depth pass;
// composited ahead (eyes exchanged: each eye's view keeps its own depth) they are what render makes.
TEST(FrameCompositor, DepthFramesTakeTheTablesAgreeWithGlAndComeAhead) {
  const Profile profile = test::small_panel_profile();
  const PackedLayout layout = layout_for(profile, "hdmi-fp-720p60");
  const CompositorOptions options{1, std::nullopt, DepthMode::automatic};
  PackedFrame from_gl, from_tables, flat;
  {
    CompositeEnvironment gl("gl");
    FrameCompositor compositor(profile, options, layout, test::shared_gl_context());
    from_gl = render_bytes(compositor, depth_frame(compositor));
    EXPECT_TRUE(compositor.depth_aware());
  }
  CompositeEnvironment table("table");
  FrameCompositor compositor(profile, options, layout, test::shared_gl_context());
  from_tables = render_bytes(compositor, depth_frame(compositor));
  EXPECT_TRUE(compositor.depth_aware());
  flat = render_bytes(compositor, test_frame(compositor));
  EXPECT_FALSE(compositor.depth_aware());
  expect_eyes_at_the_origins(from_tables, layout);
  const Difference d = difference(from_gl.rgba, from_tables.rgba);
  std::printf("depth frame, tables against GL: max %d, mean %.4f\n", d.max, d.mean);
  EXPECT_LE(d.max, 3);
  EXPECT_LT(d.mean, 0.1);
  std::size_t moved = 0;
  for (std::size_t i = 0; i < flat.rgba.size(); ++i) moved += std::abs(flat.rgba[i] - from_tables.rgba[i]) > 8 ? 1 : 0;
  std::printf("the depth moves %.2f %% of the frame's channel values by more than 8\n",
              100.0 * moved / flat.rgba.size());
  EXPECT_GT(moved, flat.rgba.size() / 4000) << "the depth must move the picture (the eyes are 6 % of the frame)";

  const gl::Texture texture = gl::make_texture_2d(GL_RGBA8, layout.packed[0], layout.packed[1]);
  const gl::Framebuffer fbo = gl::make_framebuffer(texture);
  const GlPackedTarget target{fbo.id(), texture.id(), layout.packed};
  const FrameOverlays overlays{"", false, true};
  const auto first = depth_frame(compositor), second = depth_frame(compositor, true);
  EXPECT_FALSE(compositor.render(first, overlays, {target}));
  compositor.composite_ahead(std::vector<FrameCompositor::Frame>{second}, overlays, target);
  compositor.wait_for_ahead(std::chrono::milliseconds(5000));
  EXPECT_TRUE(compositor.render(second, overlays, {target}));
  Bytes shown(static_cast<std::size_t>(layout.packed[0]) * layout.packed[1] * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo.id());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, layout.packed[0], layout.packed[1], GL_RGBA, GL_UNSIGNED_BYTE, shown.data());
  EXPECT_EQ(shown, render_bytes(compositor, second, overlays).rgba);
}

TEST(FrameCompositor, StillsAreTheComposedEyesPackedBySignal) {
  const auto context = test::shared_gl_context();
  const Profile profile = test::small_panel_profile();
  StereoPair views{{test::photo_chart(kViewW, kViewH), 16.0 / 9.0}, {test::zone_plate(kViewW, kViewH), 16.0 / 9.0}};
  for (const char* name : {"hdmi-fp-720p60", "sbs", "left"}) {
    SCOPED_TRACE(name);
    const Signal signal = *find_signal(name);
    // What convert wrote before the facade: compose, then pack_eyes.
    const Image expected = pack_eyes(signal, GlCompositor(profile, {1, std::nullopt}, context).compose(views));
    FrameCompositor compositor(profile, {1, std::nullopt}, packed_layout(signal, profile.display.resolution), context);
    const Image still = compositor.render_still(views);
    ASSERT_EQ(still.width(), expected.width());
    ASSERT_EQ(still.height(), expected.height());
    EXPECT_EQ(test::max_abs_difference(still, expected), 0.0);
  }
}

}  // namespace test_frame_compositor
}  // namespace
}  // namespace nelf
