#pragma once
// One frame of a PipeWire video node, as the `pipewire:` source reads it (inputs/pipewire_capture):
// a buffer in shared memory in one of the formats below, turned into tightly packed 8-bit pixels:
// BGRx and BGRA copied as they are (ByteOrder::bgrx), 8-bit RGB in any other byte order reordered
// into RGBA; 8-bit YUV (what cameras, capture cards' nodes and encoders send) goes through swscale
// into RGBA, with the node's matrix and range.
#include <optional>
#include <string>
#include <vector>

// SPA's headers are C: compound literals and designated initialisers that -Wpedantic rejects in C++.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <spa/buffer/buffer.h>
#include <spa/param/video/raw.h>
#pragma GCC diagnostic pop

#include "core/ffmpeg_raii.hpp"
#include "inputs/live_capture.hpp"

namespace nelf {

class PipeWireFrameReader {
 public:
  // The formats read, in the order a stream offers them (RGB first: a desktop's own order, nothing
  // to convert), and the same in words for a link error.
  static std::vector<spa_video_format> formats();
  static std::string formats_in_words();

  // For frames of `format`, as the stream negotiated it.
  explicit PipeWireFrameReader(const spa_video_info_raw& format);

  // Whether the format is one of those above.
  bool readable() const;

  // The frame `buffer` holds, or nothing when it holds none (empty, corrupted, or smaller than its
  // format says). A planar YUV frame may come as one spa_data a plane (as GStreamer sends it), or
  // with every plane in the first (laid out from the first plane's stride as FFmpeg lays them out).
  std::optional<CapturedImage> read(const spa_buffer& buffer);

 private:
  std::optional<CapturedImage> copy_rgb(const spa_data& data) const;
  std::optional<CapturedImage> convert_yuv(const spa_buffer& buffer);

  // Bytes a pixel of an 8-bit RGB order, and where R, G and B sit in it.
  struct PixelOrder {
    int bytes = 0, r = 0, g = 0, b = 0;
  };

  spa_video_info_raw format_;
  int width_ = 0, height_ = 0;
  std::optional<PixelOrder> rgb_;        // an RGB format
  AVPixelFormat yuv_ = AV_PIX_FMT_NONE;  // or a YUV one, as FFmpeg names it
  ffmpeg::SwsContextPtr yuv_to_rgba_;
};

}  // namespace nelf
