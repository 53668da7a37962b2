// The CPU composite table (compositor/cpu/composite_table.hpp) against the GL path it replays:
// render_eye_reduced from the same RGBA8 block means into an RGBA8 target, read back as bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "compositor/gl/gl_compositor.hpp"
#include "support/gl_test_support.hpp"

namespace nelf {
namespace {

using test::block_means;
using Bytes = std::vector<std::uint8_t>;

struct Comparison {
  int max_difference = 0;
  double mean_difference = 0.0;
  double differing = 0.0;  // fraction of channel values that differ by more than 1
  double lit = 0.0;        // mean value of the GL image (0-255)
};

// Both paths for `eye` of `profile` from a photo chart of view_w×view_h shown at `aspect`; with a
// `surface`, the depth-aware composite of both (a table recorded with depth on), else the flat one.
// `depth_rays`: the table is recorded with depth on even without a surface.
Comparison compare_paths(const Profile& profile, Eye eye, int view_w, int view_h, double aspect,
                         std::shared_ptr<const DisparitySurface> surface = nullptr, bool depth_rays = false) {
  const auto context = test::shared_gl_context();
  const CompositorOptions options{1, std::nullopt, surface || depth_rays ? DepthMode::automatic : DepthMode::off};
  const auto block = prefilter_block(profile, options, eye, view_w, view_h, aspect);
  EXPECT_EQ(view_w % block[0], 0);
  EXPECT_EQ(view_h % block[1], 0);
  const Bytes means = block_means(test::photo_chart(view_w, view_h), block);
  const int mw = view_w / block[0], mh = view_h / block[1];
  GlCompositor compositor(profile, options, context);
  const auto panel = compositor.panel();

  const gl::Texture reduced = gl::make_texture_2d(GL_RGBA8, mw, mh);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(reduced.id(), 0, 0, 0, mw, mh, GL_RGBA, GL_UNSIGNED_BYTE, means.data());
  // The eye at (3, 5) of a larger target, as in the packed frame.
  const gl::Texture target = gl::make_texture_2d(GL_RGBA8, panel[0] + 7, panel[1] + 9);
  const gl::Framebuffer fbo = gl::make_framebuffer(target);
  compositor.set_depth(eye, surface);
  compositor.render_eye_reduced(eye, {{reduced.id(), view_w, view_h, aspect}, block}, {fbo.id(), 3, 5});
  Bytes from_gl(static_cast<std::size_t>(panel[0]) * panel[1] * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(3, 5, panel[0], panel[1], GL_RGBA, GL_UNSIGNED_BYTE, from_gl.data());

  auto table = compositor.make_composite_table(eye, view_w, view_h, aspect, block);
  EXPECT_TRUE(table);
  if (!table) return {};
  EXPECT_EQ(table->panel(), panel);
  EXPECT_EQ(table->reduced_size(), (std::array<int, 2>{mw, mh}));
  EXPECT_EQ(table->has_depth(), options.depth != DepthMode::off && profile.lens_array.has_value());
  // Strides with padding on both sides, as in a packed frame.
  const std::size_t out_stride = static_cast<std::size_t>(panel[0] + 5) * 4;
  Bytes from_table(out_stride * panel[1], 77);
  const std::size_t in_stride = static_cast<std::size_t>(mw) * 4 + 12;
  Bytes padded(in_stride * mh, 0);
  for (int y = 0; y < mh; ++y)
    std::copy_n(&means[static_cast<std::size_t>(y) * mw * 4], mw * 4, &padded[static_cast<std::size_t>(y) * in_stride]);
  table->render(padded.data(), in_stride, from_table.data(), out_stride, ChannelOrder::rgba, surface.get());

  Comparison c;
  long long total = 0, differing = 0, lit = 0, count = 0;
  for (int y = 0; y < panel[1]; ++y)
    for (int x = 0; x < panel[0]; ++x)
      for (int ch = 0; ch < 4; ++ch) {
        const int a = from_gl[(static_cast<std::size_t>(y) * panel[0] + x) * 4 + ch];
        const int b = from_table[y * out_stride + static_cast<std::size_t>(x) * 4 + ch];
        const int d = std::abs(a - b);
        c.max_difference = std::max(c.max_difference, d);
        total += d, differing += d > 1, lit += ch < 3 ? a : 0, ++count;
      }
  // The padding beyond the eye's columns is untouched.
  for (int y = 0; y < panel[1]; ++y) EXPECT_EQ(from_table[y * out_stride + panel[0] * 4], 77);
  c.mean_difference = static_cast<double>(total) / count;
  c.differing = static_cast<double>(differing) / count;
  c.lit = static_cast<double>(lit) / (count * 3.0 / 4.0);
  std::printf("table against GL: max %d, mean %.4f, %.4f %% differ by more than 1, GL mean %.1f\n", c.max_difference,
              c.mean_difference, 100.0 * c.differing, c.lit);
  return c;
}

void expect_same(const Comparison& c) {
  EXPECT_GT(c.lit, 20.0);  // there is a picture to compare
  EXPECT_LE(c.max_difference, 3);
  EXPECT_LT(c.mean_difference, 0.1);
  EXPECT_LT(c.differing, 0.002);
}

TEST(CompositeTable, SmallPanelMatchesTheGlPath) {
  expect_same(compare_paths(test::small_panel_profile(), Eye::left, 480, 272, 0.0));
}

TEST(CompositeTable, HmzT1HalfSideBySideViewsMatchTheGlPathForBothEyes) {
  const Profile profile = load_profile("hmz-t1");
  for (Eye eye : {Eye::left, Eye::right}) expect_same(compare_paths(profile, eye, 960, 1080, 16.0 / 9.0));
}

TEST(CompositeTable, RotatedAndShiftedCalibrationMatchesTheGlPath) {
  Profile profile = test::small_panel_profile();
  profile.calibration[0].rotation_deg = 1.5;
  profile.calibration[0].shift_px = {2.5, -1.25};
  profile.calibration[0].pitch_scale = 1.01;
  expect_same(compare_paths(profile, Eye::left, 480, 272, 0.0));
}

TEST(CompositeTable, StockDeviceWithoutLensArrayMatchesTheGlPath) {
  expect_same(compare_paths(load_profile("hmz-t1-stock"), Eye::right, 1920, 1080, 0.0));
}

// The depth-aware table against GL's depth-aware pass (elemental_depth_lookup.frag and the strips
// taking its crossings): the same search in float and the same taps. The two floats' arithmetic
// (llvmpipe's and the compiler's) may part at a crossing's tie, which moves a tap by a texel.
TEST(CompositeTable, DepthAwareTableMatchesTheGlDepthPass) {
  const Profile profile = test::small_panel_profile();
  const Comparison depth =
      compare_paths(profile, Eye::left, 480, 272, 0.0, test::near_block_surface(profile, 480.0 / 272.0, 240, 136));
  expect_same(depth);
}

TEST(CompositeTable, DepthAwareHmzT1TableMatchesTheGlDepthPassForBothEyes) {
  const Profile profile = load_profile("hmz-t1");
  const auto surface = test::near_block_surface(profile, 16.0 / 9.0, 240, 135);
  for (Eye eye : {Eye::left, Eye::right}) expect_same(compare_paths(profile, eye, 960, 1080, 16.0 / 9.0, surface));
}

// Rotated lattice: the border parts' borrowed crossings come from the pixel the shader names.
TEST(CompositeTable, DepthAwareRotatedCalibrationMatchesTheGlDepthPass) {
  Profile profile = test::small_panel_profile();
  profile.calibration[0].rotation_deg = 1.5;
  profile.calibration[0].shift_px = {2.5, -1.25};
  expect_same(
      compare_paths(profile, Eye::left, 480, 272, 0.0, test::near_block_surface(profile, 480.0 / 272.0, 240, 136)));
}

// A table with the depth rays still renders the flat screen for frames without depth, and a flat
// surface renders what no surface does.
TEST(CompositeTable, DepthRaysWithAFlatOrNoSurfaceRenderTheFlatScreen) {
  const auto context = test::shared_gl_context();
  const Profile profile = test::small_panel_profile();
  const CompositorOptions options{1, std::nullopt, DepthMode::estimate};
  const auto block = prefilter_block(profile, options, Eye::left, 480, 272, 0.0);
  auto table = GlCompositor(profile, options, context).make_composite_table(Eye::left, 480, 272, 0.0, block);
  auto flat_table =
      GlCompositor(profile, {1, std::nullopt}, context).make_composite_table(Eye::left, 480, 272, 0.0, block);
  ASSERT_TRUE(table && flat_table);
  ASSERT_TRUE(table->has_depth());
  EXPECT_FALSE(flat_table->has_depth());
  const Bytes means = block_means(test::photo_chart(480, 272), block);
  const std::size_t in_stride = static_cast<std::size_t>(480 / block[0]) * 4;
  const std::size_t out_stride = static_cast<std::size_t>(table->panel()[0]) * 4;
  const std::size_t size = out_stride * table->panel()[1];
  Bytes flat(size), no_surface(size), flat_surface(size);
  flat_table->render(means.data(), in_stride, flat.data(), out_stride);
  table->render(means.data(), in_stride, no_surface.data(), out_stride);
  const DisparitySurface zero(ViewDisparity{120, 68, std::vector<float>(120 * 68, 0.f)});
  table->render(means.data(), in_stride, flat_surface.data(), out_stride, ChannelOrder::rgba, &zero);
  EXPECT_EQ(no_surface, flat);
  EXPECT_EQ(flat_surface, flat);
  // And a near block moves what a good part of the eye shows.
  Bytes near(size);
  table->render(means.data(), in_stride, near.data(), out_stride, ChannelOrder::rgba,
                test::near_block_surface(profile, 480.0 / 272.0, 240, 136).get());
  std::size_t moved = 0;
  for (std::size_t i = 0; i < size; ++i) moved += std::abs(int{near[i]} - int{flat[i]}) > 8 ? 1 : 0;
  std::printf("a near block changes %.1f %% of the channel values by more than 8\n", 100.0 * moved / size);
  EXPECT_GT(moved, size / 100);
  // A surface for a table recorded without the rays is a mistake of the caller.
  EXPECT_THROW(flat_table->render(means.data(), in_stride, flat.data(), out_stride, ChannelOrder::rgba, &zero),
               std::logic_error);
}

TEST(CompositeTable, OnlyForFsaa1AndThePrefiltersBlock) {
  const auto context = test::shared_gl_context();
  const Profile profile = test::small_panel_profile();
  const auto block = prefilter_block(profile, {1, std::nullopt}, Eye::left, 480, 272, 0.0);
  EXPECT_TRUE(GlCompositor(profile, {1, std::nullopt}, context).make_composite_table(Eye::left, 480, 272, 0.0, block));
  EXPECT_FALSE(
      GlCompositor(profile, {1, std::nullopt}, context).make_composite_table(Eye::left, 480, 272, 0.0, {8, 8}));
  for (int fsaa : {0, 4, 16})
    EXPECT_FALSE(
        GlCompositor(profile, {fsaa, std::nullopt}, context).make_composite_table(Eye::left, 480, 272, 0.0, block));
}

}  // namespace
}  // namespace nelf
