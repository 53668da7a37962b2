#pragma once
// `nelf convert` for video: decode → composite (GL) → encode on three threads with bounded queues.
#include <optional>
#include <string>

#include "compositor/compositor.hpp"
#include "core/pixel_limit.hpp"
#include "hmz_output/signal.hpp"
#include "hmz_output/video_encoder.hpp"
#include "inputs/stereo_layout.hpp"
#include "inputs/subtitle_track.hpp"
#include "optics/profile.hpp"
#include "player/input_files.hpp"
#include "player/subtitle_depth.hpp"

namespace nelf {

// `--burn-subs`: a subtitle track drawn into both views of every frame before compositing.
struct SubtitleBurn {
  std::string file;  // --sub-file; "" = a subtitle file beside the input, else its own track
  // --sub-parallax: of the view width, positive = in front of the screen (or, auto, of the content).
  SubtitleDepth depth;
  SubtitleStreamChoice stream;                   // --sid, --slang
  SubtitleStereo stereo = SubtitleStereo::flat;  // --sub-stereo
};

struct VideoConvertRequest {
  std::string input;  // a media file or `synthetic:[options]`
  std::string right;  // second input for layout pair
  // A video file, an image sequence pattern such as frames_%05d.png, or one image (x.png: then
  // max_frames must be 1).
  std::string output;
  InputFiles inputs;  // what no output file may replace (each frame of a sequence is checked)
  Profile profile;
  Signal signal;
  CompositorOptions compositor;
  std::optional<StereoLayout> layout;  // nullopt: detect
  bool swap_eyes = false;
  EncoderSettings encoder;
  std::optional<double> start_s, duration_s;
  std::optional<long> max_frames;
  bool quiet = false;
  bool strict = false;
  bool allow_network = false;
  std::vector<std::pair<std::string, std::string>> device_options;  // --device-option
  std::int64_t max_pixels = kDefaultMaxPixels;
  std::optional<SubtitleBurn> burn_subs;
};

// Runs the conversion. Throws UserError (status 1 for failed jobs, 130 when interrupted); leaves no
// output behind on any failure.
void convert_video(const VideoConvertRequest& request);

}  // namespace nelf
