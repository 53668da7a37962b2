// Judging vsync from timed swaps (the window display's vsync()).
#include <gtest/gtest.h>

#include "hmz_output/swap_timing.hpp"

namespace nelf {
namespace {

TEST(SwapTiming, SwapsPacedAtTheRefreshAreVsync) {
  EXPECT_TRUE(swaps_wait_for_vblank({0.0167, 0.0166, 0.0168, 0.0167, 0.0165, 0.0167}, 60.0));
  EXPECT_TRUE(swaps_wait_for_vblank({0.0417, 0.0416, 0.0418, 0.0417}, 24.0));
}

TEST(SwapTiming, SwapsThatReturnAtOnceAreNot) {
  EXPECT_FALSE(swaps_wait_for_vblank({0.0008, 0.0011, 0.0009, 0.0010, 0.0012, 0.0009}, 60.0));
}

TEST(SwapTiming, SlowIrregularSwapsAreNot) {
  // A software renderer copying a large window: slow on average, but some swaps far shorter than a
  // period, which a vblank would never allow.
  EXPECT_FALSE(swaps_wait_for_vblank({0.004, 0.015, 0.016, 0.014, 0.017, 0.015}, 60.0));
  // Far slower than the refresh: not paced by it.
  EXPECT_FALSE(swaps_wait_for_vblank({0.040, 0.041, 0.039, 0.040, 0.042, 0.040}, 60.0));
}

TEST(SwapTiming, NothingMeasuredOrNoRefresh) {
  EXPECT_FALSE(swaps_wait_for_vblank({}, 60.0));
  EXPECT_FALSE(swaps_wait_for_vblank({0.0167, 0.0167}, 0.0));
}

}  // namespace
}  // namespace nelf
