// The play loop's ticker without vsync: its ticks keep their phase through a stall, as a display's
// refreshes do, so that the refreshes a live source is told ahead (next_after) are the ones the loop
// then sleeps to.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "player/refresh_pacing.hpp"

namespace nelf {
namespace {

using Steady = std::chrono::steady_clock;
using std::chrono::milliseconds;

TEST(RefreshTicker, TicksKeepTheirPhaseThroughAStallAndAreKnownAhead) {
  const auto period = milliseconds(10);
  const auto before = Steady::now();
  playback::RefreshTicker ticker(0.010);
  const auto start = ticker.tick();  // the phase: made with the ticker
  EXPECT_GE(start, before);
  const auto on_phase = [&](Steady::time_point t) { return (t - start) % period == Steady::duration(0); };

  ticker.sleep_to_next();
  EXPECT_EQ(ticker.tick(), start + period);
  // Told ahead: the first tick at or after a time, on the same phase.
  const auto asked = Steady::now() + milliseconds(37);
  const auto told = ticker.next_after(asked);
  EXPECT_TRUE(on_phase(told));
  EXPECT_GE(told, asked);
  EXPECT_LT(told - asked, period);
  EXPECT_EQ(ticker.next_after(ticker.tick() - milliseconds(1)), ticker.tick());

  // A stall of 0.25 s: the ticker goes on from the latest tick passed, whole periods on, rather
  // than from wherever the stall ended; the loop goes on at once, then a period a tick again.
  std::this_thread::sleep_for(milliseconds(250));
  ticker.sleep_to_next();
  const auto after_stall = Steady::now();
  const auto resumed = ticker.tick();
  EXPECT_TRUE(on_phase(resumed));
  EXPECT_LE(resumed, after_stall);
  EXPECT_GT(resumed, start + milliseconds(200));
  ticker.sleep_to_next();
  EXPECT_EQ(ticker.tick(), resumed + period);
}

}  // namespace
}  // namespace nelf
