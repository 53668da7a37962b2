#include "player/progress.hpp"

#include <fmt/format.h>
#include <unistd.h>
#include <algorithm>
#include <cmath>

namespace nelf {

namespace {
std::string clock_time(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  return s >= 3600 ? fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
                   : fmt::format("{}:{:02}", s / 60, s % 60);
}
}  // namespace

ProgressReporter::ProgressReporter(std::optional<long> total_frames, Style style, std::FILE* out,
                                   Clock::time_point start)
    : total_(total_frames), style_(style), out_(out), start_(start), last_print_(start) {}

ProgressReporter::Style ProgressReporter::style_for(bool quiet, std::FILE* out) {
  if (quiet) return Style::quiet;
  return ::isatty(::fileno(out)) ? Style::bar : Style::lines;
}

std::string ProgressReporter::status(Clock::time_point now) const {
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double fps = elapsed > 0 ? frames_ / elapsed : 0.0;
  std::string text;
  if (total_ && *total_ > 0) {
    const double fraction = std::min(1.0, static_cast<double>(frames_) / static_cast<double>(*total_));
    text = fmt::format("{:3.0f}% {}/{} frames, {:.1f} fps", fraction * 100, frames_, *total_, fps);
    if (fps > 0) text += fmt::format(", ETA {}", clock_time((static_cast<double>(*total_ - frames_)) / fps));
  } else {
    text = fmt::format("{} frames, {:.1f} fps, {} elapsed", frames_, fps, clock_time(elapsed));
  }
  return text;
}

void ProgressReporter::frame_done(Clock::time_point now) {
  ++frames_;
  if (style_ == Style::quiet) return;
  const auto interval = style_ == Style::bar ? std::chrono::milliseconds(250) : std::chrono::milliseconds(5000);
  if (now - last_print_ < interval) return;
  last_print_ = now;
  if (style_ == Style::bar) {
    std::string bar;
    if (total_ && *total_ > 0) {
      const int width = 30;
      const int filled =
          static_cast<int>(width * std::min(1.0, static_cast<double>(frames_) / static_cast<double>(*total_)));
      bar = "[" + std::string(static_cast<std::size_t>(filled), '#') +
            std::string(static_cast<std::size_t>(width - filled), '.') + "] ";
    }
    print(fmt::format("\r{}{}\x1b[K", bar, status(now)));
    printed_bar_ = true;
  } else {
    print(fmt::format("nelf: {}\n", status(now)));
  }
}

void ProgressReporter::finish(const std::string& summary, Clock::time_point now) {
  if (style_ == Style::quiet) return;
  if (printed_bar_) print("\r\x1b[K");
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  print(fmt::format("nelf: {} ({} frames in {}, {:.1f} fps)\n", summary, frames_, clock_time(elapsed),
                    elapsed > 0 ? frames_ / elapsed : 0.0));
}

void ProgressReporter::print(const std::string& text) {
  if (std::fwrite(text.data(), 1, text.size(), out_) != text.size() || std::fflush(out_) != 0) style_ = Style::quiet;
}

}  // namespace nelf
