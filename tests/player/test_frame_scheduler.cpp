#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <map>
#include <random>
#include <stdexcept>
#include <vector>

#include "player/frame_scheduler.hpp"

namespace nelf {
namespace {

TEST(FrameSchedulerStale, CountsTheDueFramesButTheNewestAndChangesNothing) {
  FrameScheduler s(1 / 60.0, 1 / 30.0);
  const std::vector<double> queued{0.0, 1 / 30.0, 2 / 30.0, 3 / 30.0};
  EXPECT_EQ(s.stale(-1.0, queued), 0u);      // nothing due
  EXPECT_EQ(s.stale(0.0, queued), 0u);       // the first due: shown, not dropped
  EXPECT_EQ(s.stale(2 / 30.0, queued), 2u);  // three due: the newest shown
  EXPECT_EQ(s.stale(1.0, queued), 3u);       // all due
  EXPECT_EQ(s.stale(1.0, std::vector<double>{}), 0u);
  const FrameDecision d = s.decide(2 / 30.0, queued, false);
  EXPECT_EQ(d.drop, 2u);               // what decide() drops
  EXPECT_EQ(s.counters().dropped, 2);  // stale() counted nothing
}

// Plays `frames` frames at `fps` on a display refreshing at `hz`: at each refresh the frames decoded
// by then (decoded_at(k) ≤ the refresh's clock) are in the queue. Records which frame each refresh
// shows and checks every decision against the queue it was given.
struct Playback {
  std::vector<double> pts;                 // of every frame
  std::vector<std::optional<int>> screen;  // frame index on screen after each refresh
  std::map<int, int> refreshes_per_frame;  // how long each frame stayed
  std::vector<double> shown_offsets;       // visible_at - pts when each frame first appears
  FrameCounters counters;
  int refreshes_until_finished = -1;
};

template <typename DecodedAt, typename Jitter>
Playback play(double fps, double hz, int frames, DecodedAt decoded_at, Jitter jitter, int max_refreshes = 100000) {
  Playback p;
  for (int k = 0; k < frames; ++k) p.pts.push_back(k / fps);
  FrameScheduler scheduler(1.0 / hz, 1.0 / fps);
  std::deque<int> queue;
  int next_decoded = 0;
  std::optional<int> on_screen;
  for (int r = 0; r < max_refreshes; ++r) {
    const double visible_at = r / hz + jitter(r);
    while (next_decoded < frames && decoded_at(next_decoded) <= visible_at) queue.push_back(next_decoded++);
    std::vector<double> queued;
    for (int k : queue) queued.push_back(p.pts[k]);
    const FrameDecision d = scheduler.decide(visible_at, queued, next_decoded == frames);
    EXPECT_LE(d.drop + (d.show_front ? 1 : 0), queue.size());
    EXPECT_FALSE(d.repeat && d.show_front);
    for (std::size_t i = 0; i < d.drop; ++i) queue.pop_front();
    if (d.show_front) {
      on_screen = queue.front();
      queue.pop_front();
      p.shown_offsets.push_back(visible_at - p.pts[*on_screen]);
    }
    if (d.finished) {
      p.refreshes_until_finished = r;
      break;
    }
    if (on_screen) {
      EXPECT_EQ(d.shown_pts, p.pts[*on_screen]);
      ++p.refreshes_per_frame[*on_screen];
    }
    p.screen.push_back(on_screen);
  }
  p.counters = scheduler.counters();
  return p;
}

auto all_decoded_early = [](int) { return -1.0; };
auto no_jitter = [](int) { return 0.0; };

TEST(FrameScheduler, TwentyFourOnSixtyIsThreeTwoPulldownWithoutRepeatsOrDrops) {
  const Playback p = play(24, 60, 48, all_decoded_early, no_jitter);
  EXPECT_EQ(p.counters.shown, 48);
  EXPECT_EQ(p.counters.repeated, 0);
  EXPECT_EQ(p.counters.dropped, 0);
  // 2 s of 24 fps on 60 Hz: 120 refreshes, every frame on screen for 2 or 3 of them, alternating.
  int threes = 0, twos = 0;
  for (int k = 0; k < 47; ++k) {
    const int n = p.refreshes_per_frame.at(k);
    EXPECT_TRUE(n == 2 || n == 3) << "frame " << k << " stayed " << n;
    (n == 3 ? threes : twos)++;
    if (k > 0) {
      EXPECT_NE(n, p.refreshes_per_frame.at(k - 1)) << "cadence must alternate at frame " << k;
    }
  }
  EXPECT_EQ(threes + twos, 47);
  EXPECT_LE(std::abs(threes - twos), 1);
  EXPECT_GE(p.refreshes_until_finished, 119);  // the last frame keeps its time on screen
  EXPECT_LE(p.refreshes_until_finished, 121);
}

TEST(FrameScheduler, ThirtyOnSixtyShowsEachFrameForTwoRefreshes) {
  const Playback p = play(30, 60, 30, all_decoded_early, no_jitter);
  EXPECT_EQ(p.counters.shown, 30);
  EXPECT_EQ(p.counters.repeated, 0);
  EXPECT_EQ(p.counters.dropped, 0);
  for (int k = 0; k < 29; ++k) EXPECT_EQ(p.refreshes_per_frame.at(k), 2) << "frame " << k;
}

TEST(FrameScheduler, SixtyOnSixtyShowsEveryFrameOnce) {
  const Playback p = play(60, 60, 60, all_decoded_early, no_jitter);
  EXPECT_EQ(p.counters.shown, 60);
  EXPECT_EQ(p.counters.repeated, 0);
  EXPECT_EQ(p.counters.dropped, 0);
  for (int k = 0; k < 59; ++k) EXPECT_EQ(p.refreshes_per_frame.at(k), 1) << "frame " << k;
}

TEST(FrameScheduler, FiftyOnSixtyNeverDropsNorRepeats) {
  const Playback p = play(50, 60, 100, all_decoded_early, no_jitter);
  EXPECT_EQ(p.counters.shown, 100);
  EXPECT_EQ(p.counters.repeated, 0);
  EXPECT_EQ(p.counters.dropped, 0);
}

TEST(FrameScheduler, HundredTwentyOnSixtyDropsEveryOtherFrame) {
  const Playback p = play(120, 60, 120, all_decoded_early, no_jitter);
  EXPECT_EQ(p.counters.shown, 60);
  EXPECT_EQ(p.counters.dropped, 60);
  EXPECT_EQ(p.counters.repeated, 0);
}

TEST(FrameScheduler, ClockJitterBelowAQuarterRefreshKeepsTheCadenceClean) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter_s(-0.003, 0.003);
  std::vector<double> jitter;
  for (int i = 0; i < 1000; ++i) jitter.push_back(jitter_s(rng));
  const Playback p = play(24, 60, 96, all_decoded_early, [&](int r) { return jitter[r % jitter.size()]; });
  EXPECT_EQ(p.counters.shown, 96);
  EXPECT_EQ(p.counters.repeated, 0);
  EXPECT_EQ(p.counters.dropped, 0);
}

TEST(FrameScheduler, VideoStaysWithinOneFrameOfTheClock) {
  for (const double fps : {23.976, 24.0, 25.0, 29.97, 30.0, 50.0, 59.94, 60.0}) {
    const Playback p = play(fps, 60, static_cast<int>(fps * 3), all_decoded_early, no_jitter);
    // A frame appears no earlier than half a refresh before its pts and no later than its pts plus
    // half a refresh (the refresh nearest its time).
    for (double offset : p.shown_offsets) {
      EXPECT_GE(offset, -0.5 / 60 - 1e-9) << fps;
      EXPECT_LE(offset, 0.5 / 60 + 1e-9) << fps;
    }
    // And whatever is on screen is the frame whose interval contains the clock, give or take one.
    for (std::size_t r = 0; r < p.screen.size(); ++r) {
      if (!p.screen[r]) continue;
      const double t = r / 60.0;
      EXPECT_LE(std::abs(p.pts[*p.screen[r]] - t), 1.0 / fps + 0.5 / 60 + 1e-9) << fps << " at refresh " << r;
    }
  }
}

TEST(FrameScheduler, ALateFrameIsARepeatThenShownIfStillCurrent) {
  // Frame 10 of 30 fps (due at refresh 20) is decoded 10 ms late: refresh 20 keeps frame 9 (a
  // repeat), refresh 21 shows frame 10, which is still current (frame 11 is due at refresh 22).
  const double late = 10 / 30.0 + 0.010;
  const Playback p = play(
      30, 60, 30, [&](int k) { return k == 10 ? late : -1.0; }, no_jitter);
  EXPECT_EQ(p.counters.repeated, 1);
  EXPECT_EQ(p.counters.dropped, 0);
  EXPECT_EQ(p.counters.shown, 30);
  EXPECT_EQ(p.screen.at(20), 9);
  EXPECT_EQ(p.screen.at(21), 10);
  EXPECT_EQ(p.screen.at(22), 11);
}

TEST(FrameScheduler, AFrameDecodedAfterItsSuccessorWasDueIsDropped) {
  // Frames 10 and 11 of 30 fps arrive together 45 ms after frame 10's time: frame 10's time has
  // passed (11 is already due), so it is never shown; the refreshes in between are repeats.
  const double late = 10 / 30.0 + 0.045;
  const Playback p = play(
      30, 60, 30, [&](int k) { return (k == 10 || k == 11) ? late : -1.0; }, no_jitter);
  EXPECT_EQ(p.counters.dropped, 1);
  EXPECT_EQ(p.counters.repeated, 3);  // refreshes 20, 21 and 22 (frame 10, then 11 due, missing)
  EXPECT_EQ(p.counters.shown, 29);
  EXPECT_EQ(p.refreshes_per_frame.count(10), 0u);
  EXPECT_EQ(p.screen.at(23), 11);
}

TEST(FrameScheduler, SlowDecodingShowsEachFrameAsItArrivesAndCountsTheWaitsAsRepeats) {
  // The decoder delivers 20 fps of a 30 fps source: frame k becomes available at 1.5 k / 30. Each
  // frame is the newest there is when it arrives, so it is shown (late) rather than dropped for a
  // frame that does not exist yet; every refresh waiting for a due frame is a repeat.
  const Playback p = play(
      30, 60, 60, [](int k) { return 1.5 * k / 30.0; }, no_jitter, 400);
  EXPECT_EQ(p.counters.shown, 60);
  EXPECT_EQ(p.counters.dropped, 0);
  EXPECT_GE(p.counters.repeated, 55);  // ~3 s of refreshes for 2 s of frames
}

TEST(FrameScheduler, NothingIsShownBeforeTheFirstFrameIsDue) {
  FrameScheduler s(1 / 60.0, 1 / 24.0);
  const std::vector<double> queued = {1.0, 1.0 + 1 / 24.0};
  FrameDecision d = s.decide(0.5, queued, false);
  EXPECT_FALSE(d.show_front);
  EXPECT_FALSE(d.repeat);
  EXPECT_FALSE(d.shown_pts);
  d = s.decide(1.0 - 0.25 / 60, queued, false);  // within half a refresh of its time
  EXPECT_TRUE(d.show_front);
  EXPECT_EQ(d.drop, 0u);
  EXPECT_EQ(d.shown_pts, 1.0);
}

TEST(FrameScheduler, APausedClockShowsNothingNewAndCountsNoRepeats) {
  FrameScheduler s(1 / 60.0, 1 / 30.0);
  std::vector<double> queued = {0.0, 1 / 30.0};
  ASSERT_TRUE(s.decide(0.0, queued, false).show_front);
  queued.erase(queued.begin());
  for (int i = 0; i < 100; ++i) {
    const FrameDecision d = s.decide(0.001, queued, false);
    EXPECT_FALSE(d.show_front);
    EXPECT_FALSE(d.repeat);
  }
  EXPECT_EQ(s.counters().repeated, 0);
}

TEST(FrameScheduler, AfterASeekBackTheEarlierFramesAreShownAtOnce) {
  FrameScheduler s(1 / 60.0, 1 / 30.0);
  const std::vector<double> at_ten = {10.0};
  ASSERT_TRUE(s.decide(10.0, at_ten, false).show_front);
  s.reset();
  const std::vector<double> at_zero = {0.0, 1 / 30.0};
  const FrameDecision d = s.decide(0.0, at_zero, false);
  EXPECT_TRUE(d.show_front);
  EXPECT_EQ(d.drop, 0u);
  EXPECT_EQ(d.shown_pts, 0.0);
  EXPECT_EQ(s.counters().shown, 2);
}

TEST(FrameScheduler, WithoutANominalRateThePeriodIsEstimatedFromTimestamps) {
  FrameScheduler s(1 / 60.0, 0.0);
  EXPECT_EQ(s.frame_period(), 0.0);
  std::vector<double> queued = {0.0, 0.04, 0.08};
  s.decide(0.0, std::span(queued).subspan(0, 3), false);
  queued.erase(queued.begin());
  // Missing successor before the period is known: not a repeat.
  EXPECT_FALSE(s.decide(0.2, std::span<const double>(), false).repeat);
  s.reset();
  s.decide(0.0, std::vector<double>{0.0}, false);
  s.decide(0.04, std::vector<double>{0.04}, false);
  EXPECT_NEAR(s.frame_period(), 0.04, 1e-12);
  EXPECT_TRUE(s.decide(0.08, std::span<const double>(), false).repeat);
}

TEST(FrameScheduler, EndOfStreamFinishesAfterTheLastFramesPeriod) {
  FrameScheduler s(1 / 60.0, 1 / 30.0);
  ASSERT_TRUE(s.decide(0.0, std::vector<double>{0.0}, true).show_front);
  EXPECT_FALSE(s.decide(1 / 60.0, std::span<const double>(), true).finished);
  EXPECT_TRUE(s.decide(2 / 60.0, std::span<const double>(), true).finished);
  EXPECT_EQ(s.counters().repeated, 0);
  FrameScheduler empty(1 / 60.0, 1 / 30.0);
  EXPECT_TRUE(empty.decide(0.0, std::span<const double>(), true).finished);
}

TEST(FrameScheduler, RefusesANonPositiveRefreshPeriod) {
  EXPECT_THROW(FrameScheduler(0.0, 1 / 30.0), std::invalid_argument);
  EXPECT_THROW(FrameScheduler(1 / 60.0, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace nelf
