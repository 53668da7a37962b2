// The depth-aware composite (GlCompositor::set_depth) against the flat one and against the
// depth-aware CPU reference (compositor/reference.cpp), on llvmpipe or a GPU.
#include <gtest/gtest.h>

#include <cstdio>

#include "compositor/gl/gl_compositor.hpp"
#include "compositor/reference.hpp"
#include "support/gl_test_support.hpp"

namespace nelf {
namespace {

using test::shared_gl_context;

Image gl_eye(const Profile& profile, int fsaa, const View& view, std::shared_ptr<const DisparitySurface> surface,
             Eye eye = Eye::left) {
  GlCompositor compositor(profile, {fsaa, std::nullopt}, shared_gl_context());
  if (surface) compositor.set_depth(eye, std::move(surface));
  return compositor.compose({view, view})[static_cast<int>(eye)];
}

// The left third of the view near (250 mm), the rest on the screen (hmz-t1: 1 m): δ/W per texel.
std::shared_ptr<const DisparitySurface> near_block(const Profile& profile, const View& view, int width, int height) {
  const EyeMapping m = make_eye_mapping(profile, Eye::left, view.aspect());
  const DepthGeometry g = depth_geometry(profile, m);
  const float near_px = static_cast<float>(disparity_mm_from_depth(g, 250.0) / g.screen_size_mm.x * width);
  ViewDisparity d{width, height, std::vector<float>(static_cast<std::size_t>(width) * height, 0.f)};
  for (int y = height / 4; y < 3 * height / 4; ++y)
    for (int x = width / 6; x < width / 2; ++x) d.d[static_cast<std::size_t>(y) * width + x] = near_px;
  return std::make_shared<const DisparitySurface>(d);
}

TEST(DepthComposite, AFlatSurfaceRendersExactlyWhatNoSurfaceDoes) {
  const Profile profile = test::small_panel_profile();
  const View view{test::photo_chart(480, 270), 0.0};
  const auto flat = std::make_shared<const DisparitySurface>(ViewDisparity{120, 68, std::vector<float>(120 * 68, 0.f)});
  for (int fsaa : {0, 1, 4}) {
    const double difference =
        test::max_abs_difference(gl_eye(profile, fsaa, view, flat), gl_eye(profile, fsaa, view, nullptr));
    std::printf("fsaa %d: flat surface vs none: largest difference %g\n", fsaa, difference);
    EXPECT_LE(difference, 1e-6) << "fsaa " << fsaa;
  }
}

TEST(DepthComposite, GlMatchesTheDepthAwareReferenceAndDiffersFromTheFlatScreen) {
  const Profile profile = test::small_panel_profile();
  const View view{test::photo_chart(480, 270), 0.0};
  const auto surface = near_block(profile, view, 240, 135);
  const EyeMapping m = make_eye_mapping(profile, Eye::left, view.aspect());
  const Image reference = reference_eye_image(m, view.image, *surface, depth_geometry(profile, m), 16);
  const Image flat_reference = reference_eye_image(m, view.image, 16);
  const Image depth = gl_eye(profile, 1, view, surface);
  const double db = test::psnr(depth, reference), flat_db = test::psnr(gl_eye(profile, 1, view, nullptr), reference);
  const double reference_shift = test::psnr(flat_reference, reference);
  std::printf(
      "depth-aware GL vs depth-aware reference %.2f dB; flat GL vs it %.2f dB; the references differ by %.2f dB\n", db,
      flat_db, reference_shift);
  EXPECT_LT(reference_shift, 36.0) << "the near block must change the reference";
  EXPECT_GE(db, 43.7) << "border strips taking the flat screen's depth give 43.2 dB";
  EXPECT_GE(db - flat_db, 5.0) << "the depth-aware GL path must follow the surface";
}

}  // namespace
}  // namespace nelf
