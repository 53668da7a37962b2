#pragma once
// Opening a media input with FFmpeg under nelf's network rule (DESIGN.md §11): unless the user
// passes --allow-network, FFmpeg may read local files and pipes only — the input itself and every
// URL it names (HLS segments, concat lists, ...) — and with a bound on how long opening a local
// file may wait. One place, for the video, the audio and the packets carried into an output.
#include <atomic>
#include <chrono>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/ffmpeg_raii.hpp"

namespace nelf::ffmpeg {

// True for what FFmpeg opens by protocol ("http://…", "pipe:0") rather than as a local file name.
bool is_url(const std::string& path);

// What the guard stopped while a context opened or read its input. Lives as long as the context it
// watches (open_input points the context at it).
struct InputGuard {
  bool allow_network = false;
  // How long opening and probing a local regular file may take without --allow-network. A local
  // file opens in milliseconds; only a demuxer that waits for more can take long: a "live" HLS
  // playlist (no #EXT-X-ENDLIST) whose entries do not open is reloaded every target duration
  // (found by fuzzing: #EXT-X-TARGETDURATION:100 kept probe waiting 200 s). Pipes, devices and
  // network inputs may rightly wait for their writer or server and get no bound.
  std::chrono::milliseconds opening_limit{15000};

  std::string refused_protocol;  // the first protocol refused, e.g. "http"; empty: none
  bool opening_stopped = false;  // opening took longer than opening_limit and was interrupted
  std::optional<std::chrono::steady_clock::time_point> opening_deadline;  // set while opening
  // Set from another thread: FFmpeg gives up what it waits for (a capture device's next frame).
  std::atomic<bool> interrupted{false};
};

// avformat_open_input for `path` (a file name, made a "file:" URL so a colon in it is no protocol,
// or a URL) into `format`; returns its status (< 0: an AVERROR). Unless guard.allow_network, every
// URL the demuxer opens on a protocol other than file or pipe is refused and recorded in `guard`,
// and opening a regular file is interrupted after guard.opening_limit (until find_stream_info).
// With `device` (a libavdevice input format: v4l2, x11grab, lavfi, …), `path` is the device's own
// name for its input (/dev/video0, :0.0, a filter graph), opened as it is, with `device_options`
// (KEY, VALUE: the device's own, as ffmpeg -video_size sets them); the keys the device does not take
// are put in `unknown`.
int open_input(FormatContextPtr& format, const std::string& path, InputGuard& guard,
               const AVInputFormat* device = nullptr,
               const std::vector<std::pair<std::string, std::string>>& device_options = {},
               std::vector<std::string>* unknown = nullptr);

// avformat_find_stream_info under the same guard, `options` as FFmpeg takes them (one dictionary per
// stream, or null); ends the opening deadline, so that reading later is never interrupted by it.
int find_stream_info(AVFormatContext* format, InputGuard& guard, AVDictionary** options = nullptr);

// The one line for an input the guard stopped, if it did ("list.m3u8: opening it needs network
// access (http); pass --allow-network", or that opening was given up after the limit).
std::optional<std::string> guard_stop(const std::string& path, const InputGuard& guard);

}  // namespace nelf::ffmpeg
