#pragma once
// Progress of a conversion on stderr: a live bar (percent, fps, ETA) on a terminal, a plain line
// every few seconds otherwise (logs, pipes), nothing when quiet. Progress is only a diagnostic: when
// it cannot be written (stderr a closed pipe, a terminal that is gone) it stops, the job goes on.
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>

namespace nelf {

class ProgressReporter {
 public:
  enum class Style { bar, lines, quiet };
  using Clock = std::chrono::steady_clock;

  // `total_frames` when known (for percent and ETA). `style` defaults to bar on a terminal, else lines.
  ProgressReporter(std::optional<long> total_frames, Style style, std::FILE* out = stderr,
                   Clock::time_point start = Clock::now());
  static Style style_for(bool quiet, std::FILE* out = stderr);

  // One more frame done; prints when it is time to.
  void frame_done(Clock::time_point now = Clock::now());
  // The final line (always printed unless quiet).
  void finish(const std::string& summary, Clock::time_point now = Clock::now());

  long frames() const { return frames_; }
  // The text of the current status, e.g. "42% 120/288 frames, 23.5 fps, ETA 0:07".
  std::string status(Clock::time_point now) const;

 private:
  // Writes `text`; a failed write turns the reporter quiet instead of failing the job.
  void print(const std::string& text);

  std::optional<long> total_;
  Style style_;
  std::FILE* out_;
  long frames_ = 0;
  Clock::time_point start_, last_print_;
  bool printed_bar_ = false;
};

}  // namespace nelf
