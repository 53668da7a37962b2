// The play decode thread applies a view format asked for on the render thread (a key changed the
// optics) before it decodes the next frame, and frames carry the format they were made in.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <optional>
#include <thread>
#include <vector>

#include "inputs/source.hpp"
#include "player/frame_queue.hpp"

namespace nelf {
namespace {

// Endless 8×4 views at 10 fps in whatever block was last negotiated (any block that divides them).
class FormatFollowingSource final : public Source {
 public:
  SourceInfo info() const override {
    SourceInfo info;
    info.frame_rate = 10;
    info.view = {8, 4, 2.0};
    return info;
  }
  std::optional<StereoVideoFrame> next() override {
    StereoVideoFrame f;
    f.width = 8;
    f.height = 4;
    f.block = block_;
    f.left.assign(static_cast<std::size_t>(8 / block_[0]) * (4 / block_[1]) * 4, 0);
    f.right = f.left;
    f.pts_s = 0.1 * static_cast<double>(frames_++);
    return f;
  }
  ViewFormat negotiate(const ViewFormat& wanted) override {
    negotiated_on = std::this_thread::get_id();
    block_ = 8 % wanted.block[0] == 0 && 4 % wanted.block[1] == 0 ? wanted.block : std::array<int, 2>{1, 1};
    return {block_};
  }
  std::atomic<std::thread::id> negotiated_on{};

 private:
  std::array<int, 2> block_{1, 1};
  long frames_ = 0;
};

TEST(FrameQueue, AViewFormatAskedForIsNegotiatedOnTheDecodeThreadAndCarriedByTheNextFrames) {
  FormatFollowingSource source;
  playback::FrameQueue queue(2);
  std::thread decoder([&] { playback::decode_loop(source, queue); });
  const auto next_frame = [&] {
    EXPECT_TRUE(queue.wait_for_frame(std::chrono::seconds(5)));
    return queue.pop(0, true);
  };
  EXPECT_EQ(next_frame()->block, (std::array<int, 2>{1, 1}));
  queue.negotiate({{2, 2}});
  // Frames decoded before the request keep their whole views; the next ones are 2×2 means.
  std::vector<std::array<int, 2>> blocks;
  while (blocks.size() < 6) blocks.push_back(next_frame()->block);
  const std::thread::id decode_thread = decoder.get_id();
  queue.stop();
  decoder.join();
  EXPECT_EQ(blocks.back(), (std::array<int, 2>{2, 2}));
  const auto first_reduced = std::find(blocks.begin(), blocks.end(), std::array<int, 2>{2, 2});
  EXPECT_TRUE(std::all_of(first_reduced, blocks.end(), [](auto b) { return b == std::array<int, 2>{2, 2}; }));
  EXPECT_EQ(source.negotiated_on.load(), decode_thread);
}

// What a stepped clock waits for before each refresh: a full queue, or the end of a stream shorter
// than the queue (and stop() ends the wait however full the queue is).
TEST(FrameQueue, WaitUntilFullReturnsWithAFullQueueOrAtTheEnd) {
  FormatFollowingSource endless;
  playback::FrameQueue queue(4);
  std::thread decoder([&] { playback::decode_loop(endless, queue); });
  queue.wait_until_full();
  bool end = true;
  EXPECT_EQ(queue.snapshot(end).size(), 4u);
  EXPECT_FALSE(end);
  queue.pop(0, true);
  queue.wait_until_full();
  EXPECT_EQ(queue.snapshot(end).size(), 4u);
  queue.stop();
  decoder.join();

  class ThreeFrames final : public Source {
   public:
    SourceInfo info() const override { return {}; }
    std::optional<StereoVideoFrame> next() override {
      if (frames_ == 3) return std::nullopt;
      StereoVideoFrame f;
      f.pts_s = 0.1 * frames_++;
      return f;
    }

   private:
    int frames_ = 0;
  } short_clip;
  playback::FrameQueue short_queue(4);
  std::thread short_decoder([&] { playback::decode_loop(short_clip, short_queue); });
  short_queue.wait_until_full();
  EXPECT_EQ(short_queue.snapshot(end).size(), 3u);
  EXPECT_TRUE(end);
  short_queue.stop();
  short_decoder.join();

  playback::FrameQueue stopped(4);
  stopped.stop();
  stopped.wait_until_full();  // returns at once
}

// A live source's frames are made whether nelf reads them or not: when nelf is held up (its first
// composite, a slow refresh) the queue keeps the newest, and the decoder goes on reading instead of
// waiting for room and then handing on frames as old as the stall.
TEST(FrameQueue, ALiveSourcesQueueKeepsTheNewestFramesWhenFull) {
  FormatFollowingSource endless;
  playback::FrameQueue queue(3, playback::FrameQueue::WhenFull::drop_oldest);
  std::thread decoder([&] { playback::decode_loop(endless, queue); });
  // Read on past the capacity: the oldest queued frame moves on.
  bool end = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  std::vector<double> queued;
  while ((queued = queue.snapshot(end)).empty() || queued.front() < 1.0) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the decoder waited for room";
    std::this_thread::yield();
  }
  queue.stop();
  decoder.join();
  queued = queue.snapshot(end);
  ASSERT_EQ(queued.size(), 3u);
  for (std::size_t i = 1; i < queued.size(); ++i) EXPECT_NEAR(queued[i] - queued[i - 1], 0.1, 1e-9);

  // A file's decoder waits for room: the first frames stay.
  FormatFollowingSource file;
  playback::FrameQueue waiting(3);
  std::thread file_decoder([&] { playback::decode_loop(file, waiting); });
  waiting.wait_until_full();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(waiting.snapshot(end), (std::vector<double>{0.0, 0.1, 0.2}));
  waiting.stop();
  file_decoder.join();
}

}  // namespace
}  // namespace nelf
