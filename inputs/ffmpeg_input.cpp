#include "inputs/ffmpeg_input.hpp"

#include <fmt/format.h>

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

namespace nelf::ffmpeg {
namespace {

using IoOpen = int (*)(AVFormatContext*, AVIOContext**, const char*, int, AVDictionary**);

// FFmpeg's own io_open (not public API): what a fresh context starts with.
IoOpen default_io_open() {
  static const IoOpen open = [] {
    AVFormatContext* context = avformat_alloc_context();
    const IoOpen found = context != nullptr ? context->io_open : nullptr;
    avformat_free_context(context);
    return found;
  }();
  return open;
}

bool is_local_protocol(const char* protocol) {
  return protocol != nullptr && (std::strcmp(protocol, "file") == 0 || std::strcmp(protocol, "pipe") == 0);
}

// Every URL a demuxer opens comes through here (the input, then HLS segments, concat entries, …).
// FFmpeg's protocol_whitelist refuses them too, but only as "Invalid data" or "Invalid argument"
// for a playlist: this records which protocol was refused, so the user is told what to pass.
int guarded_io_open(AVFormatContext* context, AVIOContext** pb, const char* url, int flags, AVDictionary** options) {
  // A nested demuxer's context may have copied io_open but not opaque: the whitelist still holds.
  auto* guard = static_cast<InputGuard*>(context->opaque);
  if (guard != nullptr && !guard->allow_network) {
    const char* protocol = avio_find_protocol_name(url);
    if (!is_local_protocol(protocol)) {
      if (guard->refused_protocol.empty()) guard->refused_protocol = protocol != nullptr ? protocol : "unknown";
      return AVERROR(EPERM);
    }
  }
  return default_io_open()(context, pb, url, flags, options);
}

// Once a URL was refused there is nothing left to wait for: a live HLS playlist (no #EXT-X-ENDLIST)
// whose segments are refused would otherwise be reloaded every target duration, up to
// m3u8_hold_counters (1000) times, before opening gives up (~17 min for 1 s segments). FFmpeg
// calls this at least every 100 ms while it waits.
int interrupt_when_stopped(void* opaque) {
  auto* guard = static_cast<InputGuard*>(opaque);
  if (guard->interrupted.load() || !guard->refused_protocol.empty()) return 1;
  if (guard->opening_deadline && std::chrono::steady_clock::now() >= *guard->opening_deadline) {
    guard->opening_stopped = true;
    return 1;
  }
  return 0;
}

bool is_regular_file(const std::string& path) {
  struct stat info {};
  return ::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode);
}

}  // namespace

bool is_url(const std::string& path) { return path.find("://") != std::string::npos || path.rfind("pipe:", 0) == 0; }

int open_input(FormatContextPtr& format, const std::string& path, InputGuard& guard, const AVInputFormat* device,
               const std::vector<std::pair<std::string, std::string>>& device_options,
               std::vector<std::string>* unknown) {
  const std::string url = device != nullptr || is_url(path) ? path : "file:" + path;
  AVFormatContext* raw = avformat_alloc_context();
  if (raw == nullptr) return AVERROR(ENOMEM);
  AVDictionary* raw_options = nullptr;
  raw->interrupt_callback = AVIOInterruptCB{interrupt_when_stopped, &guard};
  if (!guard.allow_network) {
    if (default_io_open() == nullptr) {
      avformat_free_context(raw);
      return AVERROR_BUG;
    }
    raw->opaque = &guard;
    raw->io_open = guarded_io_open;
    if (device == nullptr && !is_url(path) && is_regular_file(path))
      guard.opening_deadline = std::chrono::steady_clock::now() + guard.opening_limit;
    // Kept as the second line of defence, and for what reaches FFmpeg without io_open.
    av_dict_set(&raw_options, "protocol_whitelist", "file,pipe", 0);
    // A local HLS playlist without #EXT-X-ENDLIST is "live": while it lists nothing that opens,
    // FFmpeg reloads it every target duration up to m3u8_hold_counters (1000) times. Nothing else
    // writes to it while nelf reads (found by fuzzing): give up after two reloads that bring nothing.
    av_dict_set(&raw_options, "m3u8_hold_counters", "2", 0);
  }
  for (const auto& [key, value] : device_options) av_dict_set(&raw_options, key.c_str(), value.c_str(), 0);
  const int opened = avformat_open_input(&raw, url.c_str(), device, &raw_options);  // frees raw on failure
  DictionaryPtr unused(raw_options);
  if (unknown)
    for (const auto& [key, value] : device_options)
      if (av_dict_get(unused.get(), key.c_str(), nullptr, 0)) unknown->push_back(key);
  if (opened >= 0) format.reset(raw);
  return opened;
}

int find_stream_info(AVFormatContext* format, InputGuard& guard, AVDictionary** options) {
  const int found = avformat_find_stream_info(format, options);
  guard.opening_deadline.reset();
  return found;
}

std::optional<std::string> guard_stop(const std::string& path, const InputGuard& guard) {
  if (!guard.refused_protocol.empty())
    return fmt::format("{}: opening it needs network access ({}); pass --allow-network", path, guard.refused_protocol);
  if (guard.opening_stopped)
    return fmt::format(
        "{}: still not open after {:g} s, given up (a live playlist whose entries do not open?); check what it lists",
        path, std::chrono::duration<double>(guard.opening_limit).count());
  return std::nullopt;
}

}  // namespace nelf::ffmpeg
