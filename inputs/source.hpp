#pragma once
// A Source: stereo frames from an input, split into the two views the way the layout says: a media
// file in any layout (sbs, tab, fp, mono …, `alt` frame-sequential, `pair` = a second file for the
// right view), a still (JPS, MPO, an image pair) or the built-in `synthetic:` clip. Shared by
// `nelf convert` and `nelf play`, so that both honour --layout, --right and --swap-eyes identically.
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/audio_stream.hpp"
#include "core/carried_streams.hpp"
#include "core/frames.hpp"
#include "core/pixel_limit.hpp"
#include "inputs/stereo_layout.hpp"
#include "optics/profile.hpp"

namespace nelf {

// What to open; the driver table (inputs/source_drivers.hpp) picks the driver that reads it.
struct SourceRequest {
  std::string input;                   // a media file, a still image or `synthetic:[options]`
  std::string right;                   // second input for layout pair
  std::optional<StereoLayout> layout;  // nullopt: detect
  bool swap_eyes = false;
  std::optional<double> start_s;                // start here (seconds from the start of the input)
  bool quiet = false;                           // no line describing the input (warnings are printed all the same)
  bool allow_network = false;                   // FFmpeg protocols beyond file and pipe
  std::int64_t max_pixels = kDefaultMaxPixels;  // --max-pixels: larger frames are refused undecoded
  // The display the frames are shown on, where depth matters (`--depth` other than off): a
  // synthetic scene films itself for its emulated screen (matched_to_display), so that the depth it
  // has is the depth the viewer sees.
  std::shared_ptr<const Profile> display = nullptr;  // initialised: positional SourceRequest{…} may end before it
  // Attach the depth the source knows to its frames (StereoVideoFrame::disparity: the synthetic
  // scenes' exact depth), for `--depth auto`; sources that know none ignore it.
  bool known_depth = false;
  // Set from elsewhere (Ctrl-C): a live source waiting, while it opens, for what it reads (a window
  // that is not there yet) gives up, with status 130.
  const std::atomic<bool>* stop = nullptr;
  // --device-option KEY=VALUE for a capture device (v4l2:, device:): its own options, as ffmpeg
  // takes -video_size or -input_format before -i.
  std::vector<std::pair<std::string, std::string>> device_options{};
};

// What a source says about its stream once it is open.
struct SourceInfo {
  double frame_rate = 0.0;              // frames per second of the stereo frames (alt: half the file's)
  std::optional<double> duration_s;     // from pts_s 0, when known
  std::optional<long> expected_frames;  // stereo frames from pts_s 0, when known
  bool seekable = false;                // seek() can succeed
  bool live = false;                    // next() waits for frames made in real time (a capture)
  bool still = false;                   // one picture (a photo): play keeps it on screen until told otherwise
  std::string description;              // one line naming the input, its size and layout
  ViewGeometry view;                    // of every frame; what negotiate() formats are sized from
};

class Source {
 public:
  virtual ~Source() = default;
  virtual SourceInfo info() const = 0;
  // The next frame, or nullopt at the end. Damaged data is skipped and counted (lost_frames());
  // unrecoverable problems throw UserError.
  virtual std::optional<StereoVideoFrame> next() = 0;
  // Positions the source so that next() returns the frames at or after `seconds` (on the pts_s
  // timeline). Throws UserError (one line) when the input cannot seek: the
  // default, for sources whose info() says seekable is false.
  virtual void seek(double seconds);
  // From the next frame on (seeks included), deliver the views in the `wanted` format when the
  // input allows it (one block for both views, a stream swscale can crop: see
  // VideoSource::reduce_regions); otherwise whole views. Returns the format the next frames carry.
  // The caller asks once it knows info().view, and again when what it wants changes. The default
  // (the synthetic source, pair inputs, stills) always delivers whole views.
  virtual ViewFormat negotiate(const ViewFormat& /*wanted*/) { return {}; }
  // The sound that goes with the video, decoded as `format` asks, on the pts_s timeline (from the
  // start or the requested start): a file's audio, the synthetic clip's tone; or why there is none,
  // in words ("no audio stream", "the audio cannot be decoded (…)"). Each call opens a new stream.
  virtual OpenedAudio open_audio(AudioFormat /*format*/) const { return {nullptr, "no audio stream"}; }
  // The input's audio tracks that open_audio() can choose among (AudioFormat::track), in the
  // file's order; empty when it has none or only one made-up sound (the synthetic clip's tone).
  virtual std::vector<AudioTrack> audio_tracks() const { return {}; }
  // The encoded streams a file output copies as they are (a file's audio, subtitles, chapters and
  // metadata), on the pts_s timeline; null when the input has none to copy (the synthetic clip:
  // its sound is open_audio()'s to encode). Throws UserError when they cannot be opened.
  virtual std::unique_ptr<CarriedStreams> open_carried_streams() const { return nullptr; }
  // Frames lost or damaged so far (decode errors, read errors, frames promised but missing).
  virtual std::int64_t lost_frames() const { return 0; }
  // From another thread: ends a live source (info().live), whose next() may wait for the next
  // frame as long as nothing changes: a next() waiting returns nullopt within 0.1 s, and every
  // later one at once. Sources that never wait ignore it.
  virtual void interrupt() {}
  // From play's thread, at each refresh of a display that refreshes at a fixed rate: it began at
  // `refresh_ns` (CLOCK_MONOTONIC) and the next begins `period_ns` later. A live source that can
  // time its frames to it passes it on (glx-stereo: the game's buffer swaps return at nelf's
  // refreshes, as vsync does); the others ignore it.
  virtual void refresh_at(std::int64_t /*refresh_ns*/, std::int64_t /*period_ns*/) {}
};

}  // namespace nelf
