#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

#include "analysis/comfort_zone.hpp"

namespace nelf {
namespace {

// The boundaries solved for the focal distance give back Shibata et al.'s lines.
TEST(ComfortZone, TheRangeEndsOnShibatasBoundaries) {
  for (double vergence : {1.0, 2.0, 3.0, 4.0}) {
    const AccommodationRange r = comfortable_accommodation(vergence);
    EXPECT_NEAR(1.129 * r.farthest_diopters + 0.442, vergence, 1e-12);
    EXPECT_NEAR(1.035 * r.nearest_diopters - 0.626, vergence, 1e-12);
    EXPECT_TRUE(r.contains(vergence)) << "focusing where the eyes converge is always comfortable";
  }
  // Converged at 40 cm: comfortable focus from 1.82 D (55 cm) to 3.02 D (33 cm).
  const AccommodationRange desk = comfortable_accommodation(2.5);
  EXPECT_NEAR(desk.farthest_diopters, 1.823, 1e-3);
  EXPECT_NEAR(desk.nearest_diopters, 3.020, 1e-3);
  EXPECT_FALSE(desk.contains(1.75));
  EXPECT_FALSE(desk.contains(3.25));
}

// Far away the zone reaches infinity and narrows (the paper: conflicts are less comfortable far).
TEST(ComfortZone, FarAwayItReachesInfinityAndNarrows) {
  const AccommodationRange far = comfortable_accommodation(0.25);
  EXPECT_EQ(far.farthest_diopters, 0.0);
  EXPECT_TRUE(far.contains(0.0));
  const AccommodationRange near = comfortable_accommodation(4.0);
  EXPECT_LT((comfortable_accommodation(1.0).nearest_diopters - comfortable_accommodation(1.0).farthest_diopters),
            near.nearest_diopters - near.farthest_diopters);
}

TEST(ComfortZone, ANegativeOrUnknownVergenceIsRefused) {
  EXPECT_THROW(comfortable_accommodation(-0.5), std::invalid_argument);
  EXPECT_THROW(comfortable_accommodation(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(comfortable_accommodation(std::numeric_limits<double>::infinity()), std::invalid_argument);
}

}  // namespace
}  // namespace nelf
