// The defect compensation on GL and through the compositor facade: the two GL passes give what the
// CPU gives (to a code value), every path of the facade hides the same defects at the same pixels,
// and a profile without a map (or with compensation off) gives the frames it gave before.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "compositor/frame_compositor.hpp"
#include "compositor/gl/gl_defect_compensation.hpp"
#include "hmz_output/packing.hpp"
#include "hmz_output/signal.hpp"
#include "optics/defect_compensation.hpp"
#include "optics/defect_map.hpp"
#include "support/gl_test_support.hpp"

namespace nelf {
namespace {

using test::block_means;
using Bytes = std::vector<std::uint8_t>;

class CompositeEnvironment {
 public:
  explicit CompositeEnvironment(const char* choice) { ::setenv("NELF_COMPOSITE", choice, 1); }
  ~CompositeEnvironment() { ::unsetenv("NELF_COMPOSITE"); }
};

Bytes read_rgba(const gl::Framebuffer& fbo, std::array<int, 2> size) {
  Bytes rgba(static_cast<std::size_t>(size[0]) * size[1] * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo.id());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, size[0], size[1], GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  return rgba;
}

int max_difference(const Bytes& a, const Bytes& b) {
  EXPECT_EQ(a.size(), b.size());
  int d = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

// A plan for a 24×16 panel by hand: dead and stuck pixels, shares near both ends of the range, and
// pixels that take shares of two defects.
EyeDefectPlan hand_made_plan() {
  EyeDefectPlan plan;
  plan.panel = {24, 16};
  const auto dead = [](int x, int y) { return PixelDefect{Eye::left, x, y, DefectKind::dead, {0, 0, 0}}; };
  const auto stuck = [](int x, int y, std::array<std::uint8_t, 3> rgb) {
    return PixelDefect{Eye::left, x, y, DefectKind::stuck, rgb};
  };
  plan.corrections = {
      {dead(5, 5), {{2, 5, 0.3f}, {8, 5, 0.3f}, {5, 2, 0.2f}, {5, 8, 0.2f}}},
      {stuck(11, 5, {255, 255, 255}), {{8, 5, 0.25f}, {14, 5, 0.25f}, {11, 2, 0.25f}, {11, 8, 0.25f}}},
      {stuck(17, 10, {255, 0, 40}), {{14, 10, 0.5f}, {20, 10, 0.5f}}},
      {dead(3, 13), {{0, 13, 0.9f}, {6, 13, 0.9f}}},
      {dead(23, 15), {{20, 15, 1.f}}},
      {dead(9, 9), {}},  // nothing to make up for it with: left alone
  };
  return plan;
}

TEST(GlDefectCompensation, AddsWhatTheCpuAddsToACodeValue) {
  const auto context = test::shared_gl_context();
  const std::array<int, 2> size{40, 30};
  const std::array<std::optional<std::pair<int, int>>, 2> origins{std::pair{3, 2}, std::nullopt};
  const auto plan = std::make_shared<const EyeDefectPlan>(hand_made_plan());
  std::mt19937 random(16);
  Bytes rgba(static_cast<std::size_t>(size[0]) * size[1] * 4);
  for (std::size_t i = 0; i < rgba.size(); ++i) rgba[i] = i % 4 == 3 ? 255 : static_cast<std::uint8_t>(random() % 256);
  // Near white around one defect and near black around another: both clip.
  for (int x = 0; x < 12; ++x) std::fill_n(&rgba[((2 + 13) * size[0] + 3 + x) * 4], 3, std::uint8_t{250});
  for (int x = 14; x < 24; ++x) std::fill_n(&rgba[((2 + 5) * size[0] + 3 + x) * 4], 3, std::uint8_t{6});
  Bytes expected = rgba;
  compensate_packed_eyes({plan, nullptr}, origins, expected.data(), static_cast<std::size_t>(size[0]) * 4, 8);
  ASSERT_NE(expected, rgba);

  // A display's packed frame (BGRA8) and a plain RGBA8 one.
  for (bool bgra : {true, false}) {
    SCOPED_TRACE(bgra ? "BGRA8" : "RGBA8");
    const gl::Texture texture =
        bgra ? gl::make_bgra8_texture_2d(size[0], size[1]) : gl::make_texture_2d(GL_RGBA8, size[0], size[1]);
    const gl::Framebuffer fbo = gl::make_framebuffer(texture);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(texture.id(), 0, 0, 0, size[0], size[1], GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    GlDefectCompensation compensation;
    compensation.apply({plan, nullptr}, origins, {fbo.id(), texture.id(), size});
    const Bytes shown = read_rgba(fbo, size);
    EXPECT_LE(max_difference(shown, expected), 1);
    // Exactly as it was wherever no share lands (the defects themselves included).
    std::set<std::pair<int, int>> shares;
    for (const auto& c : plan->corrections)
      for (const auto& s : c.shares) shares.insert({s.x + 3, s.y + 2});
    long changed_elsewhere = 0;
    for (int y = 0; y < size[1]; ++y)
      for (int x = 0; x < size[0]; ++x)
        if (!shares.count({x, y}))
          for (int c = 0; c < 4; ++c) {
            const std::size_t i = (static_cast<std::size_t>(y) * size[0] + x) * 4 + c;
            changed_elsewhere += shown[i] != rgba[i];
          }
    EXPECT_EQ(changed_elsewhere, 0);
  }
}

constexpr int kViewW = 480, kViewH = 272;

FrameCompositor::Frame test_frame(const FrameCompositor& compositor) {
  auto frame = std::make_shared<StereoVideoFrame>();
  frame->width = kViewW;
  frame->height = kViewH;
  frame->block = compositor.wanted_block(kViewW, kViewH, 0.0);
  frame->left = block_means(test::photo_chart(kViewW, kViewH), frame->block);
  frame->right = block_means(test::zone_plate(kViewW, kViewH), frame->block);
  return frame;
}

// The 320×180 test panel with defects spread over the lit middle of both eyes: dead, stuck at
// white and stuck at a colour that tells R from B.
Profile profile_with_defects() {
  Profile profile = test::small_panel_profile();
  auto map = std::make_shared<DefectMap>();
  for (int k = 0; k < 24; ++k) {
    const Eye eye = k % 2 ? Eye::right : Eye::left;
    const int x = 90 + 7 * k, y = 50 + 3 * k;
    switch (k % 3) {
      case 0:
        map->defects.push_back({eye, x, y, DefectKind::dead, {0, 0, 0}});
        break;
      case 1:
        map->defects.push_back({eye, x, y, DefectKind::stuck, {255, 255, 255}});
        break;
      default:
        map->defects.push_back({eye, x, y, DefectKind::stuck, {255, 20, 0}});
    }
  }
  profile.correction.defects = map;
  return profile;
}

// The packed-frame pixels that take a share of `compositor`'s plans.
std::set<std::pair<int, int>> share_pixels(const FrameCompositor& compositor) {
  std::set<std::pair<int, int>> pixels;
  for (Eye eye : {Eye::left, Eye::right}) {
    const auto plan = compositor.defect_plan(eye);
    const auto& origin = compositor.layout().origins[static_cast<int>(eye)];
    if (!plan || !origin) continue;
    for (const auto& c : plan->corrections)
      for (const auto& s : c.shares) pixels.insert({origin->first + s.x, origin->second + s.y});
  }
  return pixels;
}

// The pixels where `a` and `b` differ.
std::set<std::pair<int, int>> differing(const Bytes& a, const Bytes& b, int width) {
  std::set<std::pair<int, int>> pixels;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    if (a[i] != b[i]) pixels.insert({static_cast<int>(i / 4 % width), static_cast<int>(i / 4 / width)});
  return pixels;
}

struct Rendered {
  Bytes gl_target, bytes;
  std::set<std::pair<int, int>> shares;
  bool planned = false;
};

// One frame through one path ("gl" or "table") into a display's GL target and into bytes.
Rendered render_both(const Profile& profile, const char* path, bool compensate) {
  CompositeEnvironment environment(path);
  const PackedLayout layout = packed_layout(*find_signal("sbs"), profile.display.resolution);
  CompositorOptions options{1, std::nullopt};
  options.defect_compensation = compensate;
  FrameCompositor compositor(profile, options, layout, test::shared_gl_context());
  const auto frame = test_frame(compositor);
  const gl::Texture texture = gl::make_bgra8_texture_2d(layout.packed[0], layout.packed[1]);
  const gl::Framebuffer fbo = gl::make_framebuffer(texture);
  Rendered r;
  compositor.render(frame, {}, {GlPackedTarget{fbo.id(), texture.id(), layout.packed}});
  r.gl_target = read_rgba(fbo, layout.packed);
  PackedFrame out;
  compositor.render(frame, {}, PackedTarget::bytes(out));
  r.bytes = out.rgba;
  r.shares = share_pixels(compositor);
  r.planned = compositor.defect_plan(Eye::left) && compositor.defect_plan(Eye::right);
  return r;
}

TEST(FrameCompositorDefects, EveryPathHidesTheDefectsAtTheirBundlesOnly) {
  const auto context = test::shared_gl_context();
  const Profile profile = profile_with_defects();
  const int width = packed_layout(*find_signal("sbs"), profile.display.resolution).packed[0];
  for (const char* path : {"gl", "table"}) {
    SCOPED_TRACE(path);
    const Rendered on = render_both(profile, path, true);
    const Rendered off = render_both(profile, path, false);
    ASSERT_TRUE(on.planned);
    EXPECT_FALSE(off.planned);
    ASSERT_FALSE(on.shares.empty());
    for (const auto* frame : {&on.gl_target, &on.bytes}) {
      const auto changed = differing(*frame, frame == &on.bytes ? off.bytes : off.gl_target, width);
      EXPECT_FALSE(changed.empty());
      for (const auto& p : changed) EXPECT_TRUE(on.shares.count(p)) << p.first << "," << p.second;
    }
    // The GL passes against the CPU on the same composite (the table path's GL target is
    // compensated on the CPU, in BGRA: exactly the same bytes).
    EXPECT_LE(max_difference(on.gl_target, on.bytes), std::string(path) == "gl" ? 1 : 0);
  }
}

TEST(FrameCompositorDefects, WithoutAMapOrWithCompensationOffTheFramesAreAsBefore) {
  const auto context = test::shared_gl_context();
  const Profile with_map = profile_with_defects();
  for (const char* path : {"gl", "table"}) {
    SCOPED_TRACE(path);
    const Rendered none = render_both(test::small_panel_profile(), path, true);
    const Rendered off = render_both(with_map, path, false);
    EXPECT_FALSE(none.planned);
    EXPECT_EQ(none.gl_target, off.gl_target);
    EXPECT_EQ(none.bytes, off.bytes);
  }
}

TEST(FrameCompositorDefects, FramesCompositedAheadAreHiddenAsTheOthers) {
  CompositeEnvironment table("table");
  const Profile profile = profile_with_defects();
  const PackedLayout layout = packed_layout(*find_signal("hdmi-fp-720p60"), profile.display.resolution);
  FrameCompositor compositor(profile, {1, std::nullopt}, layout, test::shared_gl_context());
  const gl::Texture texture = gl::make_bgra8_texture_2d(layout.packed[0], layout.packed[1]);
  const gl::Framebuffer fbo = gl::make_framebuffer(texture);
  const GlPackedTarget target{fbo.id(), texture.id(), layout.packed};
  const auto first = test_frame(compositor);
  auto second = std::make_shared<StereoVideoFrame>(*first);
  std::swap(second->left, second->right);
  EXPECT_FALSE(compositor.render(first, {}, {target}));
  const std::vector<FrameCompositor::Frame> next{second};
  compositor.composite_ahead(next, {}, target);
  compositor.wait_for_ahead(std::chrono::milliseconds(5000));
  EXPECT_TRUE(compositor.render(second, {}, {target}));
  const Bytes ahead = read_rgba(fbo, layout.packed);
  PackedFrame out;
  compositor.render(second, {}, PackedTarget::bytes(out));
  EXPECT_EQ(ahead, out.rgba);
  ASSERT_TRUE(compositor.defect_plan(Eye::left));
}

TEST(FrameCompositorDefects, StillsAreHiddenToo) {
  const auto context = test::shared_gl_context();
  const Profile profile = profile_with_defects();
  const PackedLayout layout = packed_layout(*find_signal("sbs"), profile.display.resolution);
  const StereoPair views{{test::photo_chart(kViewW, kViewH), 16.0 / 9.0},
                         {test::zone_plate(kViewW, kViewH), 16.0 / 9.0}};
  CompositorOptions off_options{1, std::nullopt};
  off_options.defect_compensation = false;
  FrameCompositor on(profile, {1, std::nullopt}, layout), off(profile, off_options, layout);
  const Image hidden = on.render_still(views), shown = off.render_still(views);
  const auto shares = share_pixels(on);
  ASSERT_FALSE(shares.empty());
  long changed = 0, changed_elsewhere = 0;
  for (int y = 0; y < hidden.height(); ++y)
    for (int x = 0; x < hidden.width(); ++x) {
      const Rgba a = hidden.at(x, y), b = shown.at(x, y);
      if (a.r == b.r && a.g == b.g && a.b == b.b) continue;
      ++changed;
      changed_elsewhere += shares.count({x, y}) ? 0 : 1;
    }
  EXPECT_GT(changed, 0);
  EXPECT_EQ(changed_elsewhere, 0);
}

}  // namespace
}  // namespace nelf
