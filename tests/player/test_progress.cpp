#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <thread>

#include "core/bounded_queue.hpp"
#include "player/progress.hpp"

namespace nelf {
namespace {

std::string read_all(std::FILE* f) {
  std::rewind(f);
  std::string text;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, f)) text += buffer;
  return text;
}

TEST(Progress, PlainLinesEveryFewSecondsWithPercentAndEta) {
  std::FILE* f = std::tmpfile();
  const auto t0 = ProgressReporter::Clock::now();
  ProgressReporter p(100, ProgressReporter::Style::lines, f, t0);
  for (int i = 1; i <= 50; ++i) p.frame_done(t0 + std::chrono::milliseconds(200 * i));  // 5 fps for 10 s
  const std::string text = read_all(f);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2) << text;  // at 5 s and 10 s
  EXPECT_NE(text.find("50% 50/100 frames, 5.0 fps, ETA 0:10"), std::string::npos) << text;
  std::fclose(f);
}

// Progress into a pipe nobody reads (stderr into a pager that quit) is dropped: the conversion goes
// on instead of failing on a diagnostic. (nelf ignores SIGPIPE, so the write fails with EPIPE.)
TEST(Progress, AClosedPipeEndsTheProgressNotTheJob) {
  const auto previous = std::signal(SIGPIPE, SIG_IGN);
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  ::close(fds[0]);
  std::FILE* f = ::fdopen(fds[1], "w");
  ASSERT_NE(f, nullptr);
  const auto t0 = ProgressReporter::Clock::now();
  ProgressReporter p(100, ProgressReporter::Style::lines, f, t0);
  EXPECT_NO_THROW({
    for (int i = 1; i <= 50; ++i) p.frame_done(t0 + std::chrono::milliseconds(200 * i));
    p.finish("wrote out.mkv", t0 + std::chrono::seconds(11));
  });
  EXPECT_EQ(p.frames(), 50);
  std::fclose(f);
  std::signal(SIGPIPE, previous);
}

TEST(Progress, QuietPrintsNothing) {
  std::FILE* f = std::tmpfile();
  ProgressReporter p(10, ProgressReporter::Style::quiet, f);
  for (int i = 0; i < 10; ++i) p.frame_done(ProgressReporter::Clock::now() + std::chrono::seconds(10 * i));
  p.finish("done");
  EXPECT_EQ(read_all(f), "");
  std::fclose(f);
}

TEST(Progress, BarRewritesOneLine) {
  std::FILE* f = std::tmpfile();
  const auto t0 = ProgressReporter::Clock::now();
  ProgressReporter p(4, ProgressReporter::Style::bar, f, t0);
  for (int i = 1; i <= 4; ++i) p.frame_done(t0 + std::chrono::seconds(i));
  p.finish("wrote out.mkv", t0 + std::chrono::seconds(4));
  const std::string text = read_all(f);
  EXPECT_NE(text.find("\r[###############...............]  50%"), std::string::npos) << text;
  EXPECT_NE(text.find("nelf: wrote out.mkv (4 frames in 0:04, 1.0 fps)\n"), std::string::npos) << text;
  std::fclose(f);
}

TEST(BoundedQueue, BlocksWhenFullAndDrainsAfterClose) {
  BoundedQueue<int> q(2);
  std::vector<int> got;
  std::jthread consumer([&] {
    while (auto v = q.pop()) got.push_back(*v);
  });
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(q.push(i));
  q.close();
  consumer.join();
  ASSERT_EQ(got.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(got[static_cast<std::size_t>(i)], i);
  EXPECT_FALSE(q.push(1));
}

TEST(BoundedQueue, AbortWakesABlockedProducer) {
  BoundedQueue<int> q(1);
  ASSERT_TRUE(q.push(1));
  std::jthread producer([&] { EXPECT_FALSE(q.push(2)); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  q.abort();
  producer.join();
  EXPECT_FALSE(q.pop());
}

}  // namespace
}  // namespace nelf
