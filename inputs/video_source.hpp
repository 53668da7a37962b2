#pragma once
// Decoding a video file with FFmpeg into upright RGBA frames (DESIGN.md §1 "inputs", §6 colour,
// §11 untrusted media).
//
// Colour: the stream's matrix (BT.601/709/2020) and range are honoured; an untagged matrix is
// BT.709 from 720 rows up, BT.601 below (what players do). Sources deeper than 8 bits are delivered
// as 16 bits per channel so that their precision survives until the final output (FFmpeg 5.1's
// swscale maps their peak white to 65283, not 65535: 0.4% short, under one 8-bit step).
// Rotation: the display matrix (phones recording in portrait) is applied while converting, so every
// delivered frame is upright; VideoInfo says which rotation was applied.
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/image.hpp"
#include "core/pixel_limit.hpp"
#include "inputs/multiview.hpp"
#include "inputs/stereo_metadata.hpp"

namespace nelf {

// A media file that cannot be opened or decoded; what() is one line naming the file and the cause.
class VideoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Frames wider or taller than this are refused as absurd (a corrupt or hostile header).
inline constexpr int kMaxVideoDimension = 16384;

enum class ColorMatrix { bt601, bt709, bt2020, smpte240m, fcc, rgb };
enum class ColorRange { limited, full };
std::string_view to_string(ColorMatrix matrix);
std::string_view to_string(ColorRange range);

struct VideoInfo {
  std::string path;
  std::string container;    // FFmpeg demuxer name, e.g. "matroska,webm"
  std::string video_codec;  // e.g. "h264"
  std::string pixel_format;
  int stream_index = -1;
  int coded_width = 0;  // as stored, before rotation
  int coded_height = 0;
  int sar_num = 1;  // sample (pixel) aspect ratio; 1:1 when unset
  int sar_den = 1;
  int rotation_degrees = 0;  // clockwise rotation applied to every frame: 0, 90, 180 or 270
  int width = 0;             // delivered frames, after rotation
  int height = 0;
  double display_aspect = 0.0;  // of delivered frames: width × SAR / height, after rotation
  double fps = 0.0;             // average frame rate (real base rate when unknown); 0 when unknown
  std::optional<double> duration_s;
  double start_time_s = 0.0;                // pts of the first frame, as the container says
  std::optional<std::int64_t> frame_count;  // from the container's index, when it has one
  bool seekable = true;                     // false for a pipe: seek() then fails
  bool live = false;                        // a capture device (VideoSourceOptions::device)
  int audio_streams = 0;
  int bits_per_component = 8;  // of the source (8, 10, 12, 16); delivered frames use 8 or 16
  ColorMatrix matrix = ColorMatrix::bt709;
  bool matrix_tagged = false;  // false: `matrix` is the default chosen from the height
  ColorRange range = ColorRange::limited;
  std::optional<StereoMetadata> stream_stereo;  // container/stream stereo metadata (Matroska, st3d)
  // A second view coded against the decoded one (inputs/multiview.hpp), from the streams'
  // parameters or the first packets read: FFmpeg decodes only the base view of it.
  Multiview multiview = Multiview::none;
};

// A part of every frame to deliver averaged over blocks of pixels (VideoSource::reduce_regions).
struct ReducedRegion {
  int x = 0, y = 0, width = 0, height = 0;  // pixels of the frame; width, height: multiples of the block
  int block_x = 1, block_y = 1;             // pixels averaged per output pixel, per axis
};

// One decoded frame, upright, RGBA, row 0 at the top. Exactly one of rgba8/rgba16 holds the pixels
// (tightly packed, 4 channels), ready for glTexImage2D with GL_RGBA8/GL_UNSIGNED_BYTE or
// GL_RGBA16/GL_UNSIGNED_SHORT; or, after VideoSource::reduce_regions, `reduced` holds the regions.
struct VideoFrame {
  int width = 0;
  int height = 0;
  int bits = 8;  // 8: rgba8 is filled; 16: rgba16 is filled (native endian)
  std::vector<std::uint8_t> rgba8;
  std::vector<std::uint16_t> rgba16;
  double pts_s = 0.0;  // presentation time in seconds (best-effort timestamp × time base)
  double display_aspect = 0.0;
  bool key_frame = false;
  std::optional<StereoMetadata> stereo;  // frame-packing SEI on this frame, if it carried one
  // After reduce_regions(): one tightly packed RGBA image per region, width / block_x × height /
  // block_y pixels, 1 byte per channel (bits 8) or 2 (bits 16, native endian); rgba8/rgba16 empty.
  std::vector<std::vector<std::uint8_t>> reduced;

  // Whole frames only (not after reduce_regions): pixels() is then null, to_image() throws.
  const void* pixels() const;
  // Channel c (0 = R … 3 = A) of pixel (x, y), normalised to 0..1.
  float channel(int x, int y, int c) const;
  Image to_image() const;
};

struct VideoSourceOptions {
  bool allow_network = false;  // false: FFmpeg may only use the file and pipe protocols
  bool apply_rotation = true;  // false: deliver frames as stored and leave rotation to the caller
  // --max-pixels: a stream, or a frame of it, larger than this is refused before it is decoded.
  std::int64_t max_pixels = kDefaultMaxPixels;
  // A libavdevice input format (v4l2, x11grab, lavfi, …): the path is then that device's name for
  // its input (/dev/video0, :0.0, a filter graph), read live. Empty: a file or URL.
  std::string device;
  // --device-option KEY=VALUE: the device's own options (video_size, input_format, framerate, …).
  std::vector<std::pair<std::string, std::string>> device_options{};
};

// What went wrong while decoding, so that the caller can warn (or refuse, with --strict).
struct DecodeStats {
  std::int64_t frames_decoded = 0;
  std::int64_t decode_errors = 0;   // packets the decoder rejected, frames it flagged corrupt
  std::int64_t read_errors = 0;     // demuxer errors other than end of file (truncated/damaged file)
  std::int64_t missing_frames = 0;  // at end of stream: frames the container promised but never came
  std::int64_t problems() const { return decode_errors + read_errors + missing_frames; }
};

// FFmpeg logs to stderr by default; the CLI keeps it quiet and reports problems as one line itself.
void quiet_ffmpeg_logs(bool quiet);

class VideoSource {
 public:
  // Opens `path` and its best video stream, ready to decode. Throws VideoError.
  explicit VideoSource(const std::string& path, VideoSourceOptions options = {});
  ~VideoSource();
  VideoSource(VideoSource&&) noexcept;
  VideoSource& operator=(VideoSource&&) noexcept;

  const VideoInfo& info() const;

  // The next frame in presentation order, or nullopt at the end of the stream. Damaged data is
  // skipped and counted in stats(); only unrecoverable problems throw VideoError.
  std::optional<VideoFrame> next_frame();

  const DecodeStats& stats() const;

  // From now on, deliver each frame as `regions`, each averaged over its blocks while converting
  // from the decoded YUV (swscale's area filter, exact for whole blocks): the full-resolution RGBA
  // frame is never made, which is most of the cost of a 1080p frame on a CPU. Returns false, and
  // changes nothing, when the stream cannot be delivered so: rotation metadata, a region off the
  // chroma grid or not a whole number of blocks, or a pixel format that cannot be cropped.
  // An empty list returns to whole frames. `max_bits` 8: deeper 4:2:0 (10-bit video) is averaged
  // to 8-bit RGBA, ordered-dithered (yuv_block_means.hpp), for an 8-bit output; otherwise to
  // 16 bits. What the frames then hold, they say (VideoFrame::bits).
  bool reduce_regions(std::vector<ReducedRegion> regions, int max_bits = 16);
  // The frame next_frame() returned last, converted again as now set (e.g. after reduce_regions).
  // nullopt before the first frame.
  std::optional<VideoFrame> convert_last();

  // Positions decoding so that the next frames are those at or after `seconds` (from the start of
  // the stream): seeks to the keyframe before it and decodes up to it. Throws VideoError when the
  // file cannot seek.
  void seek(double seconds);

  // The stream's stereo metadata if the container has it, else the last frame-packing SEI seen
  // while decoding (the SEI rides on keyframes only, so it is remembered).
  std::optional<StereoMetadata> stereo_metadata() const;
  // The frame-packing SEI remembered from decoding, regardless of the container.
  std::optional<StereoMetadata> frame_stereo_metadata() const;
  // From another thread: a next_frame() waiting for a device's next frame returns nothing (the
  // end), and so does every later one.
  void interrupt();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nelf
