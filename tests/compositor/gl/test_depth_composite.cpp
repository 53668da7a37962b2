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
  const auto surface = test::near_block_surface(profile, view.aspect(), 240, 135);
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
