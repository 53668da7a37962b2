// When the quad-buffer interposer returns a game's buffer swap (glx_stereo::swap_returns_ns): the
// vsync rule of `nelf run`, against nelf's refreshes as its refresh messages say them.
#include <gtest/gtest.h>

#include "inputs/glx_stereo_protocol.hpp"

namespace nelf::glx_stereo {
namespace {

constexpr std::int64_t ms = 1'000'000;

// Refreshes at 1000 ms + k · 16 ms; a frame swapped 4 ms before one is shown in it.
constexpr RefreshTiming kDisplay{1000 * ms, 16 * ms, 4 * ms};

TEST(GlxStereoSwapReturns, TheNextFrameIsSwappedTheLeadBeforeTheFirstRefreshItCanReach) {
  // A game that draws in 2 ms, swapping at 1003 ms: its next frame can reach the refresh at 1016 ms
  // (swapped by 1012 ms), so the swap returns at 1010 ms.
  EXPECT_EQ(swap_returns_ns(kDisplay, 1003 * ms, 1, 2 * ms), 1010 * ms);
  // Too late for 1016 (1011 + 2 + 4 > 1016): the one after, 1032.
  EXPECT_EQ(swap_returns_ns(kDisplay, 1011 * ms, 1, 2 * ms), 1026 * ms);
  // Exactly in time: 1010 + 2 + 4 = 1016.
  EXPECT_EQ(swap_returns_ns(kDisplay, 1010 * ms, 1, 2 * ms), 1010 * ms);
  // Refreshes that nelf said for later than now (a message read before its time) count the same.
  EXPECT_EQ(swap_returns_ns({1100 * ms, 16 * ms, 4 * ms}, 1003 * ms, 1, 2 * ms), 1094 * ms);
}

TEST(GlxStereoSwapReturns, IntervalNSkipsNMinusOneRefreshes) {
  EXPECT_EQ(swap_returns_ns(kDisplay, 1003 * ms, 2, 2 * ms), 1026 * ms);
  EXPECT_EQ(swap_returns_ns(kDisplay, 1003 * ms, 3, 2 * ms), 1042 * ms);
}

TEST(GlxStereoSwapReturns, LeadAndDrawingTimeBeyondAPeriodCountAsOnePeriod) {
  // A lead or a frame time over one period (a hiccup) would otherwise send the game back in time.
  EXPECT_EQ(swap_returns_ns({1000 * ms, 16 * ms, 40 * ms}, 1003 * ms, 1, 2 * ms),
            swap_returns_ns({1000 * ms, 16 * ms, 16 * ms}, 1003 * ms, 1, 2 * ms));
  EXPECT_EQ(swap_returns_ns(kDisplay, 1003 * ms, 1, 90 * ms), swap_returns_ns(kDisplay, 1003 * ms, 1, 16 * ms));
  EXPECT_GE(swap_returns_ns(kDisplay, 1003 * ms, 1, 90 * ms), 1003 * ms);
}

TEST(GlxStereoSwapReturns, AtOnceWithoutVsyncOrWithoutRecentRefreshes) {
  EXPECT_EQ(swap_returns_ns(kDisplay, 1003 * ms, 0, 2 * ms), 0);             // interval 0: vsync off
  EXPECT_EQ(swap_returns_ns({}, 1003 * ms, 1, 2 * ms), 0);                   // nothing said (convert)
  EXPECT_EQ(swap_returns_ns(kDisplay, 1000 * ms + 501 * ms, 1, 2 * ms), 0);  // nelf stopped saying
  EXPECT_NE(swap_returns_ns(kDisplay, 1000 * ms + 499 * ms, 1, 2 * ms), 0);
}

TEST(GlxStereoSwapReturns, WhileNelfSaysNoRefreshAVsyncGameIsPacedAt60Hz) {
  // What nelf says wins; without it (play starting, convert) `interval` periods of 60 Hz after the
  // last return, or at once when that has passed or there was none.
  EXPECT_EQ(vsync_returns_ns(kDisplay, 1003 * ms, 1, 2 * ms, 990 * ms),
            swap_returns_ns(kDisplay, 1003 * ms, 1, 2 * ms));
  EXPECT_EQ(vsync_returns_ns({}, 1003 * ms, 1, 2 * ms, 990 * ms), 990 * ms + kUntoldPeriodNs);
  EXPECT_EQ(vsync_returns_ns({}, 1003 * ms, 2, 2 * ms, 990 * ms), 990 * ms + 2 * kUntoldPeriodNs);
  EXPECT_EQ(vsync_returns_ns({}, 1030 * ms, 1, 2 * ms, 990 * ms), 1030 * ms);
  EXPECT_EQ(vsync_returns_ns({}, 1003 * ms, 1, 2 * ms, 0), 0);
  EXPECT_EQ(vsync_returns_ns({}, 1003 * ms, 0, 2 * ms, 990 * ms), 0);
}

}  // namespace
}  // namespace nelf::glx_stereo
