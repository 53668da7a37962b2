#pragma once
// The decoded frames of `nelf play` waiting for their refresh, and the decode thread that fills
// them (player.cpp's loop takes them out).
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "compositor/cpu/composite_ahead.hpp"
#include "core/frames.hpp"
#include "inputs/source.hpp"

namespace nelf::playback {

// Decoded frames waiting for their refresh. The decode thread fills it up to `capacity`; a seek
// empties it and bumps the generation so that a frame decoded before the seek is never queued.
// Frames are shared read-only from here on: the compositing-ahead worker reads the next ones while
// they wait (CompositeAhead).
class FrameQueue {
 public:
  using Frame = CompositeAhead::Frame;

  // When the queue is full: a file's decoder waits for room; a live source's frames are made in
  // real time whether nelf reads them or not, so the newest are kept and the oldest dropped (a
  // reader that waited would hand on frames as old as the stall that filled the queue).
  enum class WhenFull { wait, drop_oldest };

  explicit FrameQueue(std::size_t capacity, WhenFull when_full = WhenFull::wait)
      : capacity_(capacity), when_full_(when_full) {}

  // Decode thread: waits for room (or a seek, a new view format, or stop; never for room with
  // drop_oldest). Returns the seek target and the view format if one is pending.
  struct Work {
    std::optional<double> seek_to;
    std::optional<ViewFormat> view_format;
    std::uint64_t generation = 0;
    bool stop = false;
  };
  Work wait_for_work() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] {
      return stop_ || seek_to_ || view_format_ ||
             (!end_ && (when_full_ == WhenFull::drop_oldest || items_.size() < capacity_));
    });
    Work work{std::exchange(seek_to_, std::nullopt), std::exchange(view_format_, std::nullopt), generation_, stop_};
    return work;
  }
  void push(StereoVideoFrame frame, std::uint64_t generation) {
    std::lock_guard lock(mutex_);
    if (generation != generation_) return;  // decoded before a seek
    if (when_full_ == WhenFull::drop_oldest && items_.size() >= capacity_) items_.pop_front();
    items_.push_back(std::make_shared<const StereoVideoFrame>(std::move(frame)));
    changed_.notify_all();
  }
  void set_end(std::uint64_t generation) {
    std::lock_guard lock(mutex_);
    if (generation == generation_) end_ = true;
    changed_.notify_all();
  }
  void fail(std::exception_ptr error) {
    std::lock_guard lock(mutex_);
    error_ = error;
    end_ = true;
    changed_.notify_all();
  }

  // Render thread.
  void seek(double seconds) {
    std::lock_guard lock(mutex_);
    seek_to_ = seconds;
    ++generation_;
    items_.clear();
    end_ = false;
    changed_.notify_all();
  }
  // The views of frames decoded from now on in `wanted` format where the source allows it
  // (Source::negotiate, on the decode thread); frames already queued keep theirs.
  void negotiate(ViewFormat wanted) {
    std::lock_guard lock(mutex_);
    view_format_ = wanted;
    changed_.notify_all();
  }
  void stop() {
    std::lock_guard lock(mutex_);
    stop_ = true;
    changed_.notify_all();
  }
  // pts of the queued frames and whether the stream has ended; rethrows the decoder's failure.
  std::vector<double> snapshot(bool& end) {
    std::lock_guard lock(mutex_);
    if (error_) std::rethrow_exception(error_);
    std::vector<double> pts;
    pts.reserve(items_.size());
    for (const auto& f : items_) pts.push_back(f->pts_s);
    end = end_ && !seek_to_;
    return pts;
  }
  // Removes `drop` frames, then returns the next one if `take` (null when there is none).
  Frame pop(std::size_t drop, bool take) {
    std::lock_guard lock(mutex_);
    for (std::size_t i = 0; i < drop && !items_.empty(); ++i) items_.pop_front();
    Frame out;
    if (take && !items_.empty()) {
      out = std::move(items_.front());
      items_.pop_front();
    }
    changed_.notify_all();
    return out;
  }
  // The first `count` queued frames (fewer when fewer are there), oldest first; they stay queued.
  std::vector<Frame> front(std::size_t count) {
    std::lock_guard lock(mutex_);
    return std::vector<Frame>(items_.begin(),
                              items_.begin() + static_cast<std::ptrdiff_t>(std::min(count, items_.size())));
  }
  // Waits until the queue is full, or the stream has ended (or failed, or the queue was stopped).
  void wait_until_full() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return items_.size() >= capacity_ || (end_ && !seek_to_) || error_ || stop_; });
  }
  // Waits up to `timeout` for a frame (or the end); true when one is there.
  bool wait_for_frame(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return !items_.empty() || end_ || error_; });
    if (error_) std::rethrow_exception(error_);
    return !items_.empty();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Frame> items_;
  std::size_t capacity_;
  WhenFull when_full_;
  std::optional<double> seek_to_;
  std::optional<ViewFormat> view_format_;
  std::uint64_t generation_ = 0;
  bool end_ = false, stop_ = false;
  std::exception_ptr error_;
};

// The decode thread: fills the queue, follows seeks. Frames whose time passes while they wait are
// dropped by the scheduler. (Skipping late frames here as well was measured and is worse when
// decoding is the bottleneck: each decoded frame is late, so most were thrown away without the
// decoder catching up; jumping ahead by seeking is worse still with long GOPs.)
// `draw` (may be empty) is done to each frame before it is queued: the subtitles.
inline void decode_loop(Source& source, FrameQueue& queue, const std::function<void(StereoVideoFrame&)>& draw = {}) {
  try {
    for (;;) {
      const FrameQueue::Work work = queue.wait_for_work();
      if (work.stop) return;
      if (work.view_format) source.negotiate(*work.view_format);
      if (work.seek_to) {
        source.seek(*work.seek_to);
        continue;
      }
      auto frame = source.next();
      if (!frame) {
        queue.set_end(work.generation);
        continue;
      }
      if (draw) draw(*frame);
      queue.push(std::move(*frame), work.generation);
    }
  } catch (...) {
    queue.fail(std::current_exception());
  }
}

}  // namespace nelf::playback
