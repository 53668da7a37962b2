// The tests' master clock (player/stepped_clock.hpp): it moves only when advanced, not while paused,
// and a seek restarts it where asked.
#include <gtest/gtest.h>

#include "player/stepped_clock.hpp"

namespace nelf {
namespace {

TEST(SteppedClock, MovesOnlyWhenAdvancedAndNotWhilePaused) {
  playback::SteppedClock clock;
  EXPECT_EQ(clock.now(), 0.0);
  EXPECT_FALSE(clock.paused());
  clock.advance(0.25);
  clock.advance(0.25);
  EXPECT_EQ(clock.now(), 0.5);
  clock.set_paused(true);
  EXPECT_TRUE(clock.paused());
  clock.advance(1.0);
  EXPECT_EQ(clock.now(), 0.5);
  clock.restart_at(10.0);
  EXPECT_EQ(clock.now(), 10.0);
  clock.set_paused(false);
  clock.advance(0.5);
  EXPECT_EQ(clock.now(), 10.5);
}

}  // namespace
}  // namespace nelf
