// The eye simulator in front of the real scene (SceneDepth): the ideal an eye sees when the source
// knows its depth, the regions of the scene on the retina, and the depth-aware composite judged
// against that oracle.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "analysis/eye_simulator.hpp"
#include "compositor/reference.hpp"
#include "support/test_support.hpp"

namespace nelf {
namespace {

using test::half_resolution_hmz_toml;  // tests/support: the hmz-t1 optics on a quarter of its pixels

// Fine detail a few display footprints across, so defocus shows.
Image detailed_view(int width = 512, int height = 288) {
  Image view(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const bool check = ((x / 6) + (y / 6)) % 2 == 0;
      const float ring = static_cast<float>(0.5 + 0.5 * std::cos(0.21 * std::hypot(x - width / 2.0, y - height / 2.0)));
      view.at(x, y) = {check ? 0.85f : 0.15f, ring, static_cast<float>(x) / width, 1.f};
    }
  return view;
}

struct DepthScene {
  Profile profile = parse_profile(half_resolution_hmz_toml, "small.toml");
  Image view = detailed_view();
  EyeMapping rendering = make_eye_mapping(profile, Eye::left, 16.0 / 9.0);
  DepthGeometry geometry = depth_geometry(profile, rendering);
  EyeSimulator simulator{device_optics(profile, Eye::left), rendering, view};

  // A surface of one depth over the whole view, in the map's units (view pixels of a 128×72 map).
  SceneDepth uniform(double depth_mm) const {
    const float d = static_cast<float>(disparity_mm_from_depth(geometry, depth_mm) / geometry.screen_size_mm.x * 128);
    return {std::make_shared<const DisparitySurface>(ViewDisparity{128, 72, std::vector<float>(128 * 72, d)}),
            geometry};
  }
};

const DepthScene& setup() {
  static const DepthScene s;
  return s;
}

EyeModel eye_at(double focus_mm, int samples = 7) {
  EyeModel eye;
  eye.focus_mm = focus_mm;
  eye.pupil_samples_per_axis = samples;
  return eye;
}

std::vector<std::uint8_t> on_screen(const DepthScene& s, double focus_mm) {
  return s.simulator.on_screen_mask(eye_at(focus_mm));
}

TEST(SceneDepth, ASceneOnTheScreenIsTheScreen) {
  const DepthScene& s = setup();
  const SceneDepth flat = s.uniform(s.geometry.screen_distance_mm);
  for (double focus : {250.0, s.geometry.screen_distance_mm}) {
    const Image a = s.simulator.ideal(eye_at(focus), &flat), b = s.simulator.ideal(eye_at(focus));
    EXPECT_TRUE(std::isinf(psnr_db(a, b))) << "focus " << focus;
  }
}

TEST(SceneDepth, AnEyeFocusedAtThePlaneSeesItSharpAndTheScreenDoesNot) {
  // The whole scene at 250 mm: focused there, the eye sees what the pupil's centre sees (sharp);
  // focused at the screen it sees the plane blurred. The flat screen behaves the other way round.
  const DepthScene& s = setup();
  const SceneDepth near = s.uniform(250.0);
  const double screen = s.geometry.screen_distance_mm;
  const Image sharp = s.simulator.ideal(eye_at(screen, 1));  // one ray per direction: no defocus
  const auto mask = on_screen(s, screen);
  const double near_focused = psnr_db(s.simulator.ideal(eye_at(250.0), &near), sharp, mask);
  const double near_at_screen = psnr_db(s.simulator.ideal(eye_at(screen), &near), sharp, mask);
  const double screen_at_near = psnr_db(s.simulator.ideal(eye_at(250.0)), sharp, mask);
  std::printf("plane at 250 mm, focused on it %.2f dB, focused on the screen %.2f dB; screen seen at 250 mm %.2f dB\n",
              near_focused, near_at_screen, screen_at_near);
  EXPECT_GT(near_focused, 40.0);
  EXPECT_LT(near_at_screen, near_focused - 10.0);
  EXPECT_LT(screen_at_near, near_focused - 10.0);
}

TEST(SceneDepth, RegionsAreWhereTheChiefRayShowsThem) {
  const DepthScene& s = setup();
  std::vector<std::uint8_t> left_half(static_cast<std::size_t>(s.view.width()) * s.view.height(), 0);
  for (int y = 0; y < s.view.height(); ++y)
    for (int x = 0; x < s.view.width() / 2; ++x) left_half[static_cast<std::size_t>(y) * s.view.width() + x] = 1;
  const EyeModel eye = eye_at(s.geometry.screen_distance_mm);
  const auto region = s.simulator.view_region_mask(eye, left_half);
  const auto screen = s.simulator.on_screen_mask(eye);
  const VisualField& f = s.simulator.field();
  std::size_t in_region = 0, on = 0, misplaced = 0;
  for (int j = 0; j < f.height; ++j)
    for (int i = 0; i < f.width; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * f.width + i;
      in_region += region[k];
      on += screen[k];
      if (region[k] && !screen[k]) ++misplaced;
    }
  EXPECT_EQ(misplaced, 0u);
  EXPECT_NEAR(static_cast<double>(in_region) / on, 0.5, 0.02);
  // Through a surface in front of the screen the same view pixels are seen from the pupil's centre at
  // the same place (the centre's view is the view): the region does not move.
  const SceneDepth near = s.uniform(400.0);
  EXPECT_EQ(s.simulator.view_region_mask(eye, left_half, &near), region);
  EXPECT_THROW(s.simulator.view_region_mask(eye, std::vector<std::uint8_t>(10, 1)), std::invalid_argument);
}

TEST(SceneDepth, TheDepthAwareCompositeFollowsTheSceneAndTheFlatOneDoesNot) {
  // The oracle of issue #15: in front of a scene at 250 mm, an eye focused there sees the
  // depth-aware composite (the CPU reference) much closer to the real scene than the flat one. On
  // this small profile it measures +4.5 dB (22.6 → 27.1 dB): each 1 mm lenslet's beam still leaves
  // about a quarter of the 4 mm pupil's defocus blur of the flat screen, so the bound is +3 dB.
  const DepthScene& s = setup();
  const SceneDepth near = s.uniform(250.0);
  const Image flat = reference_eye_image(s.rendering, s.view, 4);
  const Image depth = reference_eye_image(s.rendering, s.view, *near.surface, s.geometry, 4);
  const EyeModel eye = eye_at(250.0);
  const double flat_db = s.simulator.simulate(flat, eye, &near).psnr_db;
  const double depth_db = s.simulator.simulate(depth, eye, &near).psnr_db;
  std::printf("focused at 250 mm on a scene there: flat composite %.2f dB, depth-aware %.2f dB\n", flat_db, depth_db);
  EXPECT_GT(depth_db, flat_db + 3.0);
}

}  // namespace
}  // namespace nelf
