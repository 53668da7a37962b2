#pragma once
// The sound of `nelf play`: decoded audio fed to the device ahead of its time.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "core/audio_stream.hpp"
#include "hmz_output/audio_output.hpp"

namespace nelf::playback {

// Feeds decoded audio to the device, about half a second ahead, until stopped.
class AudioFeeder {
 public:
  AudioFeeder(std::unique_ptr<AudioStream> source, AudioOutput& output) : source_(std::move(source)), output_(output) {
    thread_ = std::jthread([this](std::stop_token stop) { run(stop); });
  }
  ~AudioFeeder() {
    thread_.request_stop();
    wake_.notify_all();
  }
  AudioFeeder(const AudioFeeder&) = delete;
  AudioFeeder& operator=(const AudioFeeder&) = delete;

  // Render thread: drop what is queued and continue from `seconds`.
  void seek(double seconds) {
    std::lock_guard lock(mutex_);
    output_.restart_at(seconds);
    seek_to_ = seconds;
    ++generation_;
    ended_ = false;
    wake_.notify_all();
  }
  std::int64_t decode_errors() const { return errors_.load(); }

 private:
  void run(std::stop_token stop) {
    while (!stop.stop_requested()) {
      std::uint64_t generation;
      {
        std::unique_lock lock(mutex_);
        if (seek_to_) {
          try {
            source_->seek(*std::exchange(seek_to_, std::nullopt));
          } catch (const AudioError&) {
            ended_ = true;  // a file that cannot seek its audio plays on without it
            output_.end_of_stream();
          }
        }
        if (ended_) {
          wake_.wait_for(lock, std::chrono::milliseconds(50));
          continue;
        }
        generation = generation_;
      }
      if (output_.buffered_s() > 0.5) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        continue;
      }
      std::optional<AudioChunk> chunk;
      try {
        chunk = source_->next();
      } catch (const AudioError&) {
        chunk.reset();  // the audio is beyond repair: the video goes on, on the clock the sound left
      }
      errors_.store(source_->decode_errors());
      std::lock_guard lock(mutex_);
      if (generation != generation_) continue;  // decoded before a seek
      if (!chunk) {
        ended_ = true;
        output_.end_of_stream();
        continue;
      }
      output_.queue(*chunk);
    }
  }

  std::unique_ptr<AudioStream> source_;
  AudioOutput& output_;
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::optional<double> seek_to_;
  std::uint64_t generation_ = 0;
  bool ended_ = false;
  std::atomic<std::int64_t> errors_{0};
  std::jthread thread_;  // last: stops before the members it uses go
};

}  // namespace nelf::playback
