// The on-screen text overlay: it changes the view only inside its box, at a size relative to the
// view's height, and leaves the view alone when there is no text.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "compositor/overlays/calibration_overlay.hpp"
#include "compositor/overlays/text_overlay.hpp"
#include "support/gl_test_support.hpp"

namespace nelf {
namespace {
// This file's own names: its suite is compiled as one unit (tests/CMakeLists.txt).
namespace test_text_overlay {

std::vector<float> texture_pixels(GLuint texture, int width, int height) {
  std::vector<float> pixels(static_cast<std::size_t>(width) * height * 4);
  glGetTextureImage(texture, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(pixels.size() * sizeof(float)), pixels.data());
  return pixels;
}

struct Comparison {
  int changed_inside = 0;
  int changed_outside = 0;
  int bright_inside = 0;  // text pixels: near white
};

Comparison compare(const std::vector<float>& before, const std::vector<float>& after, int width, int height,
                   const TextOverlay::Box& box) {
  Comparison c;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 4;
      bool changed = false;
      for (int k = 0; k < 4; ++k) changed |= before[i + k] != after[i + k];
      const bool inside = x >= box.x && x < box.x + box.width && y >= box.y && y < box.y + box.height;
      if (!changed) continue;
      (inside ? c.changed_inside : c.changed_outside)++;
      if (inside && after[i] > 0.9f && after[i + 1] > 0.9f && after[i + 2] > 0.9f) c.bright_inside++;
    }
  return c;
}

class TextOverlayTest : public ::testing::Test {
 protected:
  void SetUp() override { test::shared_gl_context()->make_current(); }
};

TEST_F(TextOverlayTest, ChangesOnlyTheBoxInTheLowerThirdAndDarkensBehindTheText) {
  const Image chart = test::photo_chart(320, 180);
  const gl::Texture texture = upload_texture(chart, GL_RGBA8);
  const GlTextureView view{texture.id(), 320, 180, 0.0};
  TextOverlay overlay;
  overlay.set_text("distance 1.25 m");
  const GlTextureView shown = overlay.apply(Eye::left, view);
  EXPECT_NE(shown.texture, view.texture);
  EXPECT_EQ(shown.width, 320);
  EXPECT_EQ(shown.height, 180);

  const TextOverlay::Box box = overlay.box(Eye::left);
  EXPECT_GT(box.width, 40);
  EXPECT_LT(box.width, 320 * 0.9 + 1);
  EXPECT_NEAR(box.x + box.width / 2.0, 160, 1.0);        // centred
  EXPECT_GE(box.y + box.height / 2.0, 180 * 2.0 / 3.0);  // in the lower third
  EXPECT_LE(box.y + box.height, 180);

  const auto before = texture_pixels(view.texture, 320, 180);
  const auto after = texture_pixels(shown.texture, 320, 180);
  const Comparison c = compare(before, after, 320, 180, box);
  EXPECT_EQ(c.changed_outside, 0);
  EXPECT_GT(c.changed_inside, box.width * box.height * 9 / 10);  // the translucent box covers it
  EXPECT_GT(c.bright_inside, 30);                                // and the letters are there
  EXPECT_TRUE(overlay.box(Eye::right).width == 0);               // the other eye was not asked
}

TEST_F(TextOverlayTest, SameApparentSizeAtAnyResolution) {
  TextOverlay overlay;
  overlay.set_text("IPD 63.5 mm");
  const gl::Texture small = upload_texture(test::photo_chart(320, 180), GL_RGBA8);
  const gl::Texture large = upload_texture(test::photo_chart(1280, 720), GL_RGBA16F);
  overlay.apply(Eye::left, {small.id(), 320, 180, 0.0});
  const GlTextureView shown_large = overlay.apply(Eye::right, {large.id(), 1280, 720, 0.0});
  const TextOverlay::Box a = overlay.box(Eye::left), b = overlay.box(Eye::right);
  // Relative to the view: within a few texels of 4x (fonts hint at small sizes).
  EXPECT_NEAR(b.height / 720.0, a.height / 180.0, 3.0 / 180.0);
  EXPECT_NEAR(b.width / 1280.0, a.width / 320.0, 6.0 / 320.0);
  GLint format = 0;
  glGetTextureLevelParameteriv(shown_large.texture, 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
  EXPECT_EQ(format, GL_RGBA16F);  // a 16-bit view keeps its precision
}

TEST_F(TextOverlayTest, TextChangesAreDrawnAndLongLinesFit) {
  const gl::Texture texture = upload_texture(test::photo_chart(320, 180), GL_RGBA8);
  const GlTextureView view{texture.id(), 320, 180, 0.0};
  TextOverlay overlay;
  overlay.set_text("paused");
  overlay.apply(Eye::left, view);
  const int short_width = overlay.box(Eye::left).width;
  const auto paused = texture_pixels(overlay.apply(Eye::left, view).texture, 320, 180);
  overlay.set_text("a much longer message that would not fit the view at the usual size");
  const GlTextureView shown = overlay.apply(Eye::left, view);
  const TextOverlay::Box box = overlay.box(Eye::left);
  EXPECT_GT(box.width, short_width);
  EXPECT_LE(box.width, 288);
  EXPECT_NE(texture_pixels(shown.texture, 320, 180), paused);
}

TEST_F(TextOverlayTest, AnamorphicViewsGetANarrowerBoxInTexels) {
  // A 960x1080 half-SBS view shown at 16:9: each texel is twice as wide as it is tall.
  const gl::Texture texture = upload_texture(test::photo_chart(480, 270), GL_RGBA8);
  TextOverlay overlay;
  overlay.set_text("swap eyes");
  overlay.apply(Eye::left, {texture.id(), 480, 270, 0.0});
  const int square = overlay.box(Eye::left).width;
  overlay.apply(Eye::left, {texture.id(), 480, 270, 2.0 * 480.0 / 270.0});
  EXPECT_NEAR(overlay.box(Eye::left).width, square / 2.0, 1.0);
}

// The player's CPU path draws the message into the views' bytes (cover() through draw_over): what
// apply() draws into the texture, to a code value, with square and with anamorphic texels (where
// the label is resampled).
TEST_F(TextOverlayTest, TheCoverDrawnOverTheViewsBytesIsWhatApplyDraws) {
  const int w = 480, h = 270;
  const gl::Texture texture = upload_texture(test::photo_chart(w, h), GL_RGBA8);
  const auto bytes_of = [&](GLuint id) {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(w) * h * 4);
    glGetTextureImage(id, 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(out.size()), out.data());
    return out;
  };
  const std::vector<std::uint8_t> view = bytes_of(texture.id());
  TextOverlay overlay;
  overlay.set_text("IPD 63.5 mm");
  for (const double aspect : {0.0, 2.0 * w / h}) {
    SCOPED_TRACE("display aspect " + std::to_string(aspect));
    const std::vector<std::uint8_t> gl = bytes_of(overlay.apply(Eye::left, {texture.id(), w, h, aspect}).texture);
    const Image cover = overlay.cover(w, h, aspect);
    ASSERT_EQ(cover.width(), w);
    ASSERT_EQ(cover.height(), h);
    std::vector<std::uint8_t> cpu = view;
    draw_over(cpu, cover, 8);
    int worst = 0, differ = 0, changed = 0;
    for (std::size_t i = 0; i < cpu.size(); ++i) {
      worst = std::max(worst, std::abs(cpu[i] - gl[i]));
      differ += cpu[i] != gl[i];
      changed += cpu[i] != view[i];
    }
    EXPECT_LE(worst, 2);
    EXPECT_LT(differ, static_cast<int>(cpu.size() / 100));
    const TextOverlay::Box box = overlay.box(Eye::left);
    EXPECT_GT(changed, box.width * box.height * 3 * 9 / 10);  // the box is there, all of it
  }
  overlay.set_text("");
  EXPECT_TRUE(overlay.cover(w, h, 0.0).empty());
}

TEST_F(TextOverlayTest, AViewFormatItCannotCopyIsConvertedWhole) {
  // RGB8 (no alpha): the output is RGBA16F, written by one pass over the whole view.
  const Image chart = test::photo_chart(160, 90);
  gl::Texture texture = gl::make_texture_2d(GL_RGB8, 160, 90);
  std::vector<float> rgb;
  for (const Rgba& p : chart.pixels()) rgb.insert(rgb.end(), {p.r, p.g, p.b});
  glTextureSubImage2D(texture.id(), 0, 0, 0, 160, 90, GL_RGB, GL_FLOAT, rgb.data());
  TextOverlay overlay;
  overlay.set_text("grid");
  const GlTextureView shown = overlay.apply(Eye::left, {texture.id(), 160, 90, 0.0});
  GLint format = 0;
  glGetTextureLevelParameteriv(shown.texture, 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
  EXPECT_EQ(format, GL_RGBA16F);
  const auto before = texture_pixels(texture.id(), 160, 90), after = texture_pixels(shown.texture, 160, 90);
  const TextOverlay::Box box = overlay.box(Eye::left);
  double outside_difference = 0;
  int changed_inside = 0;
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 160; ++x) {
      const bool inside = x >= box.x && x < box.x + box.width && y >= box.y && y < box.y + box.height;
      for (int k = 0; k < 3; ++k) {
        const std::size_t i = (static_cast<std::size_t>(y) * 160 + x) * 4 + k;
        const double d = std::abs(before[i] - after[i]);
        if (inside)
          changed_inside += d > 0.01;
        else
          outside_difference = std::max(outside_difference, d);
      }
    }
  EXPECT_LT(outside_difference, 1e-3);  // half-float rounding of 8-bit values only
  EXPECT_GT(changed_inside, box.width * box.height);
}

TEST_F(TextOverlayTest, EmptyTextPassesTheViewThrough) {
  const gl::Texture texture = upload_texture(test::photo_chart(64, 36), GL_RGBA8);
  const GlTextureView view{texture.id(), 64, 36, 1.5};
  TextOverlay overlay;
  const GlTextureView shown = overlay.apply(Eye::right, view);
  EXPECT_EQ(shown.texture, view.texture);
  EXPECT_EQ(shown.display_aspect, 1.5);
  EXPECT_EQ(overlay.box(Eye::right).width, 0);
  overlay.set_text("x");
  overlay.apply(Eye::right, view);
  overlay.set_text("");
  EXPECT_EQ(overlay.apply(Eye::right, view).texture, view.texture);
}

}  // namespace test_text_overlay
}  // namespace
}  // namespace nelf
