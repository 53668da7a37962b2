#pragma once
// Opening a media input with FFmpeg under nelf's network rule (DESIGN.md §11): unless the user
// passes --allow-network, FFmpeg may read local files and pipes only — the input itself and every
// URL it names (HLS segments, concat lists, ...). One place, for the video, the audio and the
// packets carried into an output.
#include <string>

#include "inputs/ffmpeg_raii.hpp"

namespace nelf::ffmpeg {

// True for what FFmpeg opens by protocol ("http://…", "pipe:0") rather than as a local file name.
bool is_url(const std::string& path);

// What the network rule refused while a context opened or read its input. Lives as long as the
// context it watches (open_input points the context at it).
struct NetworkGuard {
  bool allow_network = false;
  std::string refused_protocol;  // the first protocol refused, e.g. "http"; empty: none
};

// avformat_open_input for `path` (a file name, made a "file:" URL so a colon in it is no protocol,
// or a URL) into `format`; returns its status (< 0: an AVERROR). Unless guard.allow_network, every
// URL the demuxer opens on a protocol other than file or pipe is refused and recorded in `guard`.
int open_input(FormatContextPtr& format, const std::string& path, NetworkGuard& guard);

// The one line for an input refused by the network rule ("list.m3u8: opening it needs network access
// (http); pass --allow-network"). Call when guard.refused_protocol is not empty.
std::string network_refusal(const std::string& path, const NetworkGuard& guard);

}  // namespace nelf::ffmpeg
