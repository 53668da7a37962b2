#pragma once
// Stereo frames from a video input, split into the two views the way the layout says: a media file
// in any layout (sbs, tab, fp, mono …, `alt` frame-sequential, `pair` = a second file for the right
// view) or the built-in `synthetic:` clip. Shared by `nelf convert` (video) and `nelf play`, so that
// both honour --layout, --right and --swap-eyes identically.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/audio_stream.hpp"
#include "core/carried_streams.hpp"
#include "core/frames.hpp"
#include "core/pixel_limit.hpp"
#include "inputs/stereo_layout.hpp"

namespace nelf {

// Which block of pixels the caller wants averaged into each delivered pixel of a view of
// `view_width`×`view_height` pixels shown at `aspect` ({1, 1}: whole views). The caller decides
// (e.g. the compositor's prefilter_block for both eyes); the source only honours it.
using ViewBlockChooser = std::function<std::array<int, 2>(int view_width, int view_height, double aspect)>;

struct StereoSourceRequest {
  std::string input;                   // a media file or `synthetic:[options]`
  std::string right;                   // second input for layout pair
  std::optional<StereoLayout> layout;  // nullopt: detect
  bool swap_eyes = false;
  std::optional<double> start_s;                // start here (seconds from the start of the input)
  bool quiet = false;                           // no line describing the input (warnings are printed all the same)
  bool allow_network = false;                   // FFmpeg protocols beyond file and pipe
  ViewBlockChooser view_block;                  // empty: whole views; else as reduce_views() from the first frame
  std::int64_t max_pixels = kDefaultMaxPixels;  // --max-pixels: larger frames are refused undecoded
};

class StereoFrameSource {
 public:
  virtual ~StereoFrameSource() = default;
  // The next frame, or nullopt at the end. Damaged data is skipped and counted (lost_frames());
  // unrecoverable problems throw UserError.
  virtual std::optional<StereoVideoFrame> next() = 0;
  virtual double frame_rate() const = 0;
  virtual std::optional<long> expected_frames() const = 0;
  // Input duration in seconds from pts_s 0 when known.
  virtual std::optional<double> duration_s() const = 0;
  // Positions the source so that next() returns the frames at or after `seconds` (on the pts_s
  // timeline). Throws UserError when the input cannot seek.
  virtual void seek(double seconds) = 0;
  // From the next frame on (seeks included), deliver the views block-averaged as `choose` says for
  // this input's view size, when the input allows it (one block for both views, a stream swscale
  // can crop: see VideoSource::reduce_regions); otherwise, or with an empty `choose` or {1, 1},
  // whole views. Returns the block the next frames carry. The synthetic source and pair inputs
  // always deliver whole views.
  virtual std::array<int, 2> reduce_views(const ViewBlockChooser& /*choose*/) { return {1, 1}; }
  // The sound that goes with the video, decoded as `format` asks, on the pts_s timeline (from the
  // start or the requested start): a file's audio, the synthetic clip's tone; or why there is none,
  // in words ("no audio stream", "the audio cannot be decoded (…)"). Each call opens a new stream.
  virtual OpenedAudio open_audio(AudioFormat /*format*/) const { return {nullptr, "no audio stream"}; }
  // The encoded streams a file output copies as they are (a file's audio, subtitles, chapters and
  // metadata), on the pts_s timeline; null when the input has none to copy (the synthetic clip:
  // its sound is open_audio()'s to encode). Throws UserError when they cannot be opened.
  virtual std::unique_ptr<CarriedStreams> open_carried_streams() const { return nullptr; }
  // Frames lost or damaged so far (decode errors, read errors, frames promised but missing).
  virtual std::int64_t lost_frames() const { return 0; }
};

// Opens the input (and --right), detects the layout from the first frame and prints one line
// describing it unless quiet. Throws UserError: status 1 for inputs that cannot be used, 2 for
// options that contradict the input (same messages as `nelf convert`).
std::unique_ptr<StereoFrameSource> open_stereo_frame_source(const StereoSourceRequest& request);

}  // namespace nelf
