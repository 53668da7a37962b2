// Panel-space frames (compositor/panel_frame): placed at the layout's eye origins without the lens
// mapping, the same bytes into a display's BGRA texture as into a PackedFrame, and exactly
// place_eyes' frame in 8 bits.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "compositor/panel_frame.hpp"
#include "core/gl/objects.hpp"
#include "hmz_output/packing.hpp"
#include "hmz_output/signal.hpp"
#include "support/gl_test_support.hpp"

namespace nelf {
namespace {

// A panel of distinct values per pixel and eye, so that a misplaced or swapped eye shows.
Image ramp_panel(int width, int height, float eye) {
  Image image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      image.at(x, y) = Rgba{static_cast<float>(x) / (width - 1), static_cast<float>(y) / (height - 1), eye, 1.f};
  return image;
}

TEST(PanelFrame, PlacedAsPlaceEyesIntoBytesAndIntoAGlTexture) {
  const Signal signal = *find_signal("hdmi-fp-720p60");
  const PackedLayout layout = packed_layout(signal, {160, 90});  // the panel centred in each 1280x720 area
  const EyeImages panels = {ramp_panel(160, 90, 0.25f), ramp_panel(160, 90, 0.75f)};
  const Image expected = place_eyes(layout, panels);

  PackedFrame bytes;
  render_panel_frame(layout, panels, PackedTarget::bytes(bytes));
  ASSERT_EQ(bytes.width, 1280);
  ASSERT_EQ(bytes.height, 1470);
  ASSERT_EQ(bytes.bits, 8);
  ASSERT_EQ(bytes.rgba.size(), 1280u * 1470u * 4u);
  int wrong = 0;
  for (std::size_t i = 0; i < expected.pixels().size(); ++i) {
    const Rgba& p = expected.pixels()[i];
    const float want[4] = {p.r, p.g, p.b, p.a};
    for (int c = 0; c < 4; ++c) wrong += bytes.rgba[i * 4 + c] != std::lround(want[c] * 255.f);
  }
  EXPECT_EQ(wrong, 0);
  // Somewhere in the right eye's area a right-eye pixel, and the gap black.
  const auto at = [&](int x, int y, int c) { return bytes.rgba[(static_cast<std::size_t>(y) * 1280 + x) * 4 + c]; };
  const auto right = *layout.origins[1];
  EXPECT_EQ(at(right.first + 159, right.second + 89, 0), 255);
  EXPECT_EQ(at(right.first, right.second, 2), std::lround(0.75f * 255.f));
  EXPECT_EQ(at(640, 735, 0) + at(640, 735, 1) + at(640, 735, 2), 0);

  test::shared_gl_context()->make_current();
  const gl::Texture texture = gl::make_bgra8_texture_2d(layout.packed[0], layout.packed[1]);
  const gl::Framebuffer fbo = gl::make_framebuffer(texture);
  render_panel_frame(layout, panels, PackedTarget::gl(fbo.id(), texture.id(), layout.packed));
  std::vector<std::uint8_t> from_gl(bytes.rgba.size());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo.id());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, layout.packed[0], layout.packed[1], GL_RGBA, GL_UNSIGNED_BYTE, from_gl.data());
  gl::check_error("reading back");
  EXPECT_EQ(from_gl, bytes.rgba);  // row 0 the top row in both

  // Panels of another size than the layout's are refused.
  EXPECT_THROW(
      render_panel_frame(layout, {ramp_panel(159, 90, 0.f), ramp_panel(160, 90, 0.f)}, PackedTarget::bytes(bytes)),
      std::invalid_argument);
}

}  // namespace
}  // namespace nelf
