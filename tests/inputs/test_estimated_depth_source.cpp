#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "inputs/estimated_depth_source.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/synthetic_source.hpp"
#include "support/source_requests.hpp"

namespace nelf {
namespace {

SourceRequest planes(bool known_depth, std::shared_ptr<const Profile> display = nullptr) {
  SourceRequest r = test::quiet_request("synthetic:scene=planes,duration=0.25,size=320x180");
  r.known_depth = known_depth;
  r.display = std::move(display);
  return r;
}

// The disparity at the centre of the near plane (the middle of the left view's near region).
float near_disparity(const StereoDisparity& d, const std::vector<std::uint8_t>& near_mask) {
  double x = 0, y = 0, n = 0;
  for (int j = 0; j < 180; ++j)
    for (int i = 0; i < 320; ++i)
      if (near_mask[static_cast<std::size_t>(j) * 320 + i]) x += i, y += j, ++n;
  const ViewDisparity& v = d.left;
  const int i = static_cast<int>(x / n * v.width / 320), j = static_cast<int>(y / n * v.height / 180);
  return v.d[static_cast<std::size_t>(j) * v.width + i] * 320.f / v.width;
}

TEST(EstimatedDepthSource, EveryFrameCarriesTheEstimateCloseToTheExactDepth) {
  const SyntheticClip clip(parse_synthetic_spec(planes(false).input));
  const auto exact = clip.disparity(0);
  const auto near_mask = clip.regions(0)[0].left_mask;
  auto source = with_estimated_depth(open_source(planes(false)), false);
  int frames = 0;
  while (auto frame = source->next()) {
    ++frames;
    ASSERT_TRUE(frame->disparity);
    EXPECT_EQ(frame->disparity->origin, DisparityOrigin::estimated);
    EXPECT_NEAR(near_disparity(*frame->disparity, near_mask), near_disparity(*exact, near_mask), 2.0);
  }
  EXPECT_EQ(frames, 6);
}

TEST(EstimatedDepthSource, KnownDepthIsKeptOnlyWhereAsked) {
  auto known = open_source(planes(true));
  EXPECT_EQ(known->next()->disparity->origin, DisparityOrigin::known);
  EXPECT_EQ(with_estimated_depth(open_source(planes(true)), true)->next()->disparity->origin, DisparityOrigin::known);
  EXPECT_EQ(with_estimated_depth(open_source(planes(true)), false)->next()->disparity->origin,
            DisparityOrigin::estimated);
  // Without the request a synthetic scene keeps its depth to itself (the flat screen costs nothing).
  EXPECT_FALSE(open_source(planes(false))->next()->disparity);
}

TEST(EstimatedDepthSource, ASeekGoesThroughAndTheStreamGoesOn) {
  auto source = with_estimated_depth(open_source(planes(false)), false);
  ASSERT_TRUE(source->next());
  source->seek(0.125);
  const auto frame = source->next();
  ASSERT_TRUE(frame);
  EXPECT_NEAR(frame->pts_s, 0.125, 1e-9);
  EXPECT_TRUE(frame->disparity);
  EXPECT_EQ(source->info().expected_frames, 6);
}

TEST(SyntheticDriver, FilmsForTheDisplayItIsShownOn) {
  // hmz-t1's emulated screen: the camera's width and distance are the screen's, so the near plane's
  // disparity is 3 e (at a quarter of the screen distance) over that width.
  const auto display = std::make_shared<const Profile>(load_profile("hmz-t1"));
  const SyntheticClipSettings matched = matched_to_display(parse_synthetic_spec(planes(true).input), *display);
  const double width_mm =
      2 * matched.screen_distance_mm * std::tan(matched.horizontal_fov_deg * std::numbers::pi / 360);
  const SyntheticClip clip(matched);
  const auto frame = open_source(planes(true, display))->next();
  ASSERT_TRUE(frame && frame->disparity);
  EXPECT_NEAR(near_disparity(*frame->disparity, clip.regions(0)[0].left_mask), 3 * matched.ipd_mm * 320 / width_mm,
              1e-3);
}

}  // namespace
}  // namespace nelf
