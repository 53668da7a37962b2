#include <gtest/gtest.h>

#include <stdexcept>

#include "analysis/focus_sweep.hpp"

namespace nelf {
namespace {

TEST(FocusSweep, AccommodationStepsRunFromInfinityToTheNearest) {
  const auto steps = accommodation_steps(4.5, 0.25);
  ASSERT_EQ(steps.size(), 19u);
  EXPECT_DOUBLE_EQ(steps.front(), 0.0);
  EXPECT_DOUBLE_EQ(steps[4], 1.0);
  EXPECT_DOUBLE_EQ(steps.back(), 4.5);
  EXPECT_EQ(accommodation_steps(0.0, 0.25), std::vector<double>{0.0});
}

TEST(FocusSweep, ThePeakIsRefinedBetweenSamples) {
  // A parabola with its top at 1.3: three samples around it put the peak there exactly.
  const std::vector<double> x{0.5, 1.0, 1.5, 2.0};
  std::vector<double> y;
  for (double v : x) y.push_back(30.0 - 4.0 * (v - 1.3) * (v - 1.3));
  EXPECT_NEAR(peak_position(x, y), 1.3, 1e-9);
  // At either end the sample itself (no neighbour to refine with).
  EXPECT_DOUBLE_EQ(peak_position(x, {9, 3, 2, 1}), 0.5);
  EXPECT_DOUBLE_EQ(peak_position(x, {1, 2, 3, 9}), 2.0);
  EXPECT_THROW(peak_position({}, {}), std::invalid_argument);
  EXPECT_THROW(peak_position(x, {1, 2}), std::invalid_argument);
}

}  // namespace
}  // namespace nelf
