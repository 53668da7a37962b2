#pragma once
// Every stream of a media file as a player's track list shows it: codec, channels and layout,
// language, title, flags, attachments and chapters, and per video stream its stereo metadata and
// whether it codes a second view (`nelf probe`).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "inputs/multiview.hpp"
#include "inputs/stereo_metadata.hpp"

namespace nelf {

struct MediaStream {
  int index = 0;
  std::string type;     // "video", "audio", "subtitle", "attachment", "data"
  std::string codec;    // FFmpeg's codec name ("h264", "ac3", "subrip", "ttf"); "unknown"
  std::string profile;  // "High", "LC", …; empty when the codec has none
  std::string language, title;
  bool is_default = false, forced = false, hearing_impaired = false, visual_impaired = false;
  bool cover_art = false;  // a picture attached as a video stream (AV_DISPOSITION_ATTACHED_PIC)
  // Video.
  int width = 0, height = 0;
  double fps = 0.0;
  std::string pixel_format;
  std::optional<StereoMetadata> stereo;  // the container's (Matroska StereoMode, MP4 st3d)
  Multiview multiview = Multiview::none;
  // Audio.
  int channels = 0, sample_rate = 0;
  std::string channel_layout;  // "5.1(side)", "stereo", "6 channels"
  // Attachments (Matroska fonts, cover pictures).
  std::string filename, mimetype;
};

struct MediaChapter {
  std::int64_t id = 0;
  double start_s = 0.0, end_s = 0.0;
  std::string title;
};

struct MediaStreams {
  std::vector<MediaStream> streams;  // in the file's order
  std::vector<MediaChapter> chapters;
};

// Opens `path` (under the network rule of inputs/ffmpeg_input.hpp) and describes its streams,
// reading its first packets for the second view's NAL units. Throws VideoError.
MediaStreams describe_media_streams(const std::string& path, bool allow_network);

}  // namespace nelf
