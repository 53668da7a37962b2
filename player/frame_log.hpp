#pragma once
// `nelf play --log-frames FILE`: a CSV line per refresh that showed something (diagnostics, the
// tests and tests/bench/play_pacing.sh read it).
#include <fmt/format.h>

#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

#include "core/frame_stamp.hpp"
#include "core/user_error.hpp"
#include "player/frame_scheduler.hpp"

namespace nelf::playback {

// The times of a live source's frame (a game's window): when nelf presented it, when it was read,
// and, for a game that stamps its frames (tests/game/), which frame it was and when the game
// presented it; all CLOCK_MONOTONIC nanoseconds, so that the latency is presented − game present.
struct LiveFrameTimes {
  std::int64_t presented_ns = 0, captured_ns = 0;
  std::optional<FrameStamp> game;
};

class FrameLog {
 public:
  explicit FrameLog(const std::string& path) {
    if (path.empty()) return;
    file_ = std::fopen(path.c_str(), "w");
    if (!file_) throw UserError(fmt::format("{}: cannot write the frame log", path), 1);
    std::fputs(
        "refresh,event,pts_s,clock_s,audio_clock_s,shown,repeated,dropped,upload_ms,render_ms,present_ms,queued,"
        "ahead,presented_ns,captured_ns,game_frame,game_present_ns\n",
        file_);
  }
  ~FrameLog() {
    if (file_) std::fclose(file_);
  }
  FrameLog(const FrameLog&) = delete;
  FrameLog& operator=(const FrameLog&) = delete;
  bool enabled() const { return file_ != nullptr; }
  // Times in seconds; what was not done this refresh is 0. `queued`: decoded frames waiting at the
  // decision; `ahead`: the frame rendered was composited ahead by the worker. The live columns are
  // empty for a file.
  void write(std::int64_t refresh, const char* event, std::optional<double> pts, double clock,
             std::optional<double> audio_clock, const FrameCounters& c, double upload_s, double render_s,
             double present_s, std::size_t queued, bool ahead, const LiveFrameTimes& live = {}) {
    if (!file_) return;
    const auto ns = [](std::int64_t v) { return v > 0 ? fmt::format("{}", v) : std::string(); };
    const std::string live_columns =
        fmt::format("{},{},{},{}", ns(live.presented_ns), ns(live.captured_ns),
                    live.game ? fmt::format("{}", live.game->frame) : "", live.game ? ns(live.game->present_ns) : "");
    std::fprintf(file_, "%lld,%s,%s,%.6f,%s,%lld,%lld,%lld,%.2f,%.2f,%.2f,%zu,%d,%s\n", static_cast<long long>(refresh),
                 event, pts ? fmt::format("{:.6f}", *pts).c_str() : "", clock,
                 audio_clock ? fmt::format("{:.6f}", *audio_clock).c_str() : "", static_cast<long long>(c.shown),
                 static_cast<long long>(c.repeated), static_cast<long long>(c.dropped), upload_s * 1e3, render_s * 1e3,
                 present_s * 1e3, queued, ahead ? 1 : 0, live_columns.c_str());
  }

 private:
  std::FILE* file_ = nullptr;
};

}  // namespace nelf::playback
