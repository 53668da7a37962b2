#include <gtest/gtest.h>

#include <cmath>

#include "compositor/reference.hpp"
#include "optics/mapping.hpp"

namespace nelf {
namespace {

TEST(Mapping, HmzT1LensBlockAndScreen) {
  const Profile p = load_profile("hmz-t1");
  const EyeMapping m = make_eye_mapping(p, Eye::left, 16.0 / 9.0);
  EXPECT_EQ(m.lenses[0], 13);
  EXPECT_EQ(m.lenses[1], 7);
  EXPECT_EQ(m.first_lens[0], -6);
  EXPECT_NEAR(m.gap_mm, 3.2889, 1e-4);
  EXPECT_DOUBLE_EQ(m.render_distance_mm, 1000.0);
  // Width limited by the horizontal field of view less half the IPD: 2 (1000 tan(14.574°) − 31.5).
  EXPECT_NEAR(m.screen_size_mm.x, 2 * (1000 * std::tan(29.1484 / 2 * M_PI / 180) - 31.5), 0.05);
  EXPECT_NEAR(m.screen_size_mm.y, m.screen_size_mm.x * 9 / 16, 1e-9);
  EXPECT_DOUBLE_EQ(m.screen_centre_mm.x, 31.5);
  EXPECT_DOUBLE_EQ(make_eye_mapping(p, Eye::right, 16.0 / 9.0).screen_centre_mm.x, -31.5);
}

TEST(Mapping, CentrePixelSeesScreenCentreOfItsEye) {
  Profile p = load_profile("hmz-t1");
  p.screen.converge = false;
  const EyeMapping m = make_eye_mapping(p, Eye::left, 16.0 / 9.0);
  // The point straight ahead of the pupil lies on the axis of the central lens: it shows the screen centre.
  const auto uv = view_coordinate(m, {0.0, 0.0});
  ASSERT_TRUE(uv);
  EXPECT_NEAR(uv->x, 0.5, 1e-12);
  EXPECT_NEAR(uv->y, 0.5, 1e-12);
}

TEST(Mapping, OutsideLensBlockIsBlack) {
  const Profile p = load_profile("hmz-t1");
  const EyeMapping m = make_eye_mapping(p, Eye::left, 16.0 / 9.0);
  // 13 elemental images of 1.1316 mm cover 14.71 mm of the 15.36 mm panel: the outer columns are dark.
  EXPECT_FALSE(view_coordinate_at_pixel(m, 0.5, 360.5));
  EXPECT_FALSE(view_coordinate_at_pixel(m, 1279.5, 360.5));
}

TEST(Mapping, PrescriptionPullsScreenToFarPoint) {
  Profile p = load_profile("hmz-t1");
  p.correction.prescription_diopters = -2.0;
  EXPECT_DOUBLE_EQ(render_distance_mm(p), 500.0);
  p.screen.distance_mm = 300.0;
  EXPECT_DOUBLE_EQ(render_distance_mm(p), 300.0);
}

TEST(Mapping, FootprintMatchesDesignNote) {
  const Profile p = load_profile("hmz-t1");
  const EyeMapping m = make_eye_mapping(p, Eye::left, 16.0 / 9.0);
  // DESIGN.md §4: a pixel covers p (d_r − d_e)/d_l ≈ 3.56 mm of the screen.
  EXPECT_NEAR(pixel_footprint_uv(m).x * m.screen_size_mm.x, 0.012 * 975 / 3.28887, 1e-3);
}

TEST(Mapping, StockDeviceLetterboxesView) {
  const Profile p = load_profile("hmz-t1-stock");
  const EyeMapping m = make_eye_mapping(p, Eye::left, 2.35);
  EXPECT_DOUBLE_EQ(m.view_size_mm.x, 15.36);
  EXPECT_NEAR(m.view_size_mm.y, 15.36 / 2.35, 1e-12);
  EXPECT_FALSE(view_coordinate_at_pixel(m, 640, 2));  // the bar above the picture
  const auto uv = view_coordinate_at_pixel(m, 0.5, 360);
  ASSERT_TRUE(uv);
  EXPECT_NEAR(uv->x, 0.5 / 1280, 1e-9);
}

TEST(Reference, BilinearHitsTexelCentres) {
  Image img(2, 1);
  img.at(0, 0) = {0, 0, 0, 1};
  img.at(1, 0) = {1, 1, 1, 1};
  EXPECT_FLOAT_EQ(sample_bilinear(img, 0.25, 0.5).r, 0.f);
  EXPECT_FLOAT_EQ(sample_bilinear(img, 0.5, 0.5).r, 0.5f);
  EXPECT_FLOAT_EQ(sample_bilinear(img, 0.75, 0.5).r, 1.f);
}

}  // namespace
}  // namespace nelf
