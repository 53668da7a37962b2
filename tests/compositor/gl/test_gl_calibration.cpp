// Every calibration and geometry key moves the GL output as DESIGN.md §3 specifies, and GL agrees
// with the CPU reference for each; stock profiles letter/pillar-box; render_eye into a packed frame.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "compositor/gl/gl_compositor.hpp"
#include "compositor/reference.hpp"
#include "support/gl_test_support.hpp"

namespace nelf {
namespace {

using test::psnr;
using test::shared_gl_context;

EyeImages gl_eyes(const Profile& profile, int fsaa, const View& view) {
  GlCompositor compositor(profile, {fsaa, std::nullopt}, shared_gl_context());
  return compositor.compose({view, view});
}

// Largest difference between `moved` at (x + dx, y + dy) and `base` at (x, y) where both exist.
double translation_error(const Image& base, const Image& moved, int dx, int dy) {
  double worst = 0;
  for (int y = std::max(0, -dy); y < base.height() - std::max(0, dy); ++y)
    for (int x = std::max(0, -dx); x < base.width() - std::max(0, dx); ++x) {
      const Rgba &a = base.at(x, y), &b = moved.at(x + dx, y + dy);
      worst = std::max({worst, std::abs(double(a.r - b.r)), std::abs(double(a.g - b.g)), std::abs(double(a.b - b.b))});
    }
  return worst;
}

TEST(GlCalibration, ShiftTranslatesTheEyeImageByWholePixels) {
  const View view{test::photo_chart(480, 270), 0.0};
  const Profile base_profile = test::small_panel_profile();
  const EyeImages base = gl_eyes(base_profile, 1, view);
  struct Case {
    int dx, dy;
  };
  for (const Case c : {Case{3, 0}, Case{0, 2}, Case{-5, -1}}) {
    Profile shifted_profile = base_profile;
    shifted_profile.calibration[static_cast<int>(Eye::left)].shift_px = {double(c.dx), double(c.dy)};
    const EyeImages shifted = gl_eyes(shifted_profile, 1, view);
    const int left = static_cast<int>(Eye::left), right = static_cast<int>(Eye::right);
    // Moved by exactly (dx, dy): the images agree wherever both are defined...
    EXPECT_LE(translation_error(base[left], shifted[left], c.dx, c.dy), 1e-3) << c.dx << "," << c.dy;
    // ...and not in place (the shift had an effect), and the other eye did not move.
    EXPECT_GT(translation_error(base[left], shifted[left], 0, 0), 0.1) << c.dx << "," << c.dy;
    EXPECT_EQ(translation_error(base[right], shifted[right], 0, 0), 0.0);
  }
}

// For each key: GL (fsaa 16 and the default fsaa 1) follows the reference of the changed profile,
// and the change is large against the reference of the unchanged one.
TEST(GlCalibration, EveryGeometryKeyAgreesWithTheReference) {
  const View view{test::photo_chart(480, 270), 0.0};
  const Profile base = test::small_panel_profile();
  const Image base_reference = reference_eye_image(make_eye_mapping(base, Eye::left, view.aspect()), view.image, 16);
  struct Key {
    std::string name;
    std::function<void(Profile&)> change;
  };
  const auto& L = [](Profile& p) -> EyeCalibration& { return p.calibration[static_cast<int>(Eye::left)]; };
  const Key keys[] = {
      {"calibration.left.rotation_deg = 3", [&](Profile& p) { L(p).rotation_deg = 3.0; }},
      {"calibration.left.pitch_scale = 1.03", [&](Profile& p) { L(p).pitch_scale = 1.03; }},
      {"lens_array.rotation_deg = -2", [](Profile& p) { p.lens_array->rotation_deg = -2.0; }},
      {"lens_array.offset_mm = [0.3, -0.2]",
       [](Profile& p) {
         p.lens_array->offset_mm = {0.3, -0.2};
       }},
      {"screen.distance_mm = 600", [](Profile& p) { p.screen.distance_mm = 600.0; }},
      {"screen.width_mm = 300", [](Profile& p) { p.screen.width_mm = 300.0; }},
      {"screen.converge = false", [](Profile& p) { p.screen.converge = false; }},
      {"viewing.ipd_mm = 80", [](Profile& p) { p.viewing.ipd_mm = 80.0; }},
      {"correction.prescription_diopters = -2", [](Profile& p) { p.correction.prescription_diopters = -2.0; }},
  };
  for (const Key& key : keys) {
    Profile changed = base;
    key.change(changed);
    const Image reference = reference_eye_image(make_eye_mapping(changed, Eye::left, view.aspect()), view.image, 16);
    const EyeImages sixteen = gl_eyes(changed, 16, view), one = gl_eyes(changed, 1, view);
    const double db16 = psnr(sixteen[0], reference), db1 = psnr(one[0], reference);
    const double db_unchanged = psnr(sixteen[0], base_reference);
    std::printf("%-40s fsaa 16: %.2f dB, fsaa 1: %.2f dB vs its reference; %.2f dB vs the unchanged one\n",
                key.name.c_str(), db16, db1, db_unchanged);
    EXPECT_GE(db16, 45.0) << key.name;
    EXPECT_GE(db1, 40.0) << key.name;
    EXPECT_GE(db16 - db_unchanged, 10.0) << key.name << " did not change the output";
  }
}

// A white view of `width`×`height` on the stock HMZ-T1: the picture keeps its aspect, bars are black.
void expect_boxed(int width, int height, int expected_columns, int expected_rows) {
  const Profile stock = load_profile("hmz-t1-stock");
  Image white(width, height);
  for (Rgba& p : white.pixels()) p = {1.f, 1.f, 1.f, 1.f};
  const Image eye = gl_eyes(stock, 1, {white, 0.0})[0];
  int columns = 0, rows = 0;
  for (int x = 0; x < eye.width(); ++x) columns += eye.at(x, eye.height() / 2).r > 0.5f;
  for (int y = 0; y < eye.height(); ++y) rows += eye.at(eye.width() / 2, y).r > 0.5f;
  EXPECT_NEAR(columns, expected_columns, 1) << width << "x" << height;
  EXPECT_NEAR(rows, expected_rows, 1) << width << "x" << height;
  // Bars: the corners and the middle of each side outside the picture are exactly black.
  const int bar_x = (eye.width() - expected_columns) / 2, bar_y = (eye.height() - expected_rows) / 2;
  for (int y = 0; y < eye.height(); ++y) {
    for (int x = 0; x < eye.width(); ++x) {
      if (x < bar_x - 1 || x > eye.width() - bar_x || y < bar_y - 1 || y > eye.height() - bar_y) {
        ASSERT_EQ(eye.at(x, y).r, 0.f) << "bar pixel " << x << "," << y << " is not black";
      }
    }
  }
}

TEST(GlStock, PillarboxAndLetterboxKeepTheAspect) {
  expect_boxed(640, 480, 960, 720);    // 4:3 on 16:9: pillarbox
  expect_boxed(1920, 803, 1280, 535);  // 2.39:1: letterbox (720 · 1280/1920·803/720 rows)
  expect_boxed(1280, 720, 1280, 720);  // 16:9 fills the panel
}

// The video path: both eyes rendered by render_eye straight into a frame-packed 1280×1470 target.
TEST(GlCompositor, RenderEyeIntoAPackedFrameRegion) {
  const Profile profile = load_profile("hmz-t1");
  const View view{test::photo_chart(960, 540), 0.0};
  GlCompositor compositor(profile, {1, std::nullopt}, shared_gl_context());
  const EyeImages expected = compositor.compose({view, view});

  const gl::Texture source = upload_texture(view.image);
  const gl::Texture frame = gl::make_texture_2d(GL_RGBA16F, 1280, 1470);
  const gl::Framebuffer fbo = gl::make_framebuffer(frame);
  const float grey[4] = {0.5f, 0.5f, 0.5f, 1.f};
  glClearNamedFramebufferfv(fbo.id(), GL_COLOR, 0, grey);
  compositor.render_eye(Eye::left, {source.id(), 960, 540, 0.0}, {fbo.id(), 0, 0});
  compositor.render_eye(Eye::right, {source.id(), 960, 540, 0.0}, {fbo.id(), 0, 750});
  EXPECT_EQ(test::max_abs_difference(read_back(fbo.id(), 0, 0, 1280, 720), expected[0]), 0.0);
  EXPECT_EQ(test::max_abs_difference(read_back(fbo.id(), 0, 750, 1280, 720), expected[1]), 0.0);
  const Image gap = read_back(fbo.id(), 0, 720, 1280, 30);
  for (const Rgba& p : gap.pixels()) ASSERT_EQ(p.r, 0.5f) << "render_eye wrote outside its region";
}

}  // namespace
}  // namespace nelf
