// `nelf probe IN`: what nelf sees in a media file — size, rate, codec, colour — and which stereo
// layout it would use, with the detection rule that decided (DESIGN.md §6).
#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "app/commands.hpp"
#include "core/printable.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/stereo_layout.hpp"
#include "inputs/still_source.hpp"
#include "inputs/video_source.hpp"

namespace nelf::app {

namespace {

struct ProbeOptions {
  std::string input;
  std::string layout;
  bool swap_eyes = false;
  bool json = false;
  bool allow_network = false;
  std::int64_t max_pixels = kDefaultMaxPixels;
};

// The H.264/HEVC frame-packing SEI rides on keyframes only, so decode until the first keyframe
// (normally the very first frame) before asking for stereo metadata.
constexpr int kMaxFramesBeforeKeyframe = 300;

struct ProbeResult {
  VideoInfo info;
  std::optional<StereoMetadata> metadata;
  LayoutDecision decision;
  DecodeStats stats;
};

ProbeResult probe(const ProbeOptions& options) {
  quiet_ffmpeg_logs(true);
  // A live input has no file to describe: play and convert print what they read of it.
  SourceRequest request;
  request.input = options.input;
  if (const std::string driver(source_driver_for(request).name); driver == "x11" || driver == "device")
    throw UserError(fmt::format("{}: probe describes media files; a live input is described by play and convert",
                                printable(options.input)),
                    2);
  VideoSource source(
      options.input,
      VideoSourceOptions{.allow_network = options.allow_network, .max_pixels = options.max_pixels, .device = {}});
  int decoded = 0;
  bool any_frame = false;
  while (decoded < kMaxFramesBeforeKeyframe) {
    std::optional<VideoFrame> frame = source.next_frame();
    if (!frame) break;
    any_frame = true;
    ++decoded;
    if (frame->key_frame) break;
  }
  if (!any_frame) throw VideoError(fmt::format("{}: no video frame could be decoded", options.input));

  ProbeResult result{source.info(), source.stereo_metadata(), {}, source.stats()};
  LayoutEvidence evidence;
  if (!options.layout.empty()) evidence.flag = parse_stereo_layout(options.layout);  // checked by CLI11
  evidence.swap_eyes = options.swap_eyes;
  evidence.metadata = result.metadata;
  evidence.width = result.info.width;
  evidence.height = result.info.height;
  evidence.display_aspect = result.info.display_aspect;
  evidence.filename = options.input;
  result.decision = detect_stereo_layout(evidence);
  // FFmpeg sees an MPO's first JPEG only: its layout is the one play and convert read, the two
  // images of the file (the still reader's, which says why it chose it).
  std::string extension = std::filesystem::path(options.input).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".mpo") {
    StillOptions still;
    still.layout = evidence.flag;
    still.swap_eyes = options.swap_eyes;
    still.max_pixels = options.max_pixels;
    try {
      result.decision = load_still(options.input, still).decision;
    } catch (const StillError& e) {
      throw UserError(e.what());
    }
  }
  return result;
}

nlohmann::json optional_number(const std::optional<double>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

void print_json(const ProbeResult& r) {
  const VideoInfo& info = r.info;
  nlohmann::json out = {
      {"layout", std::string(to_string(r.decision.layout))},
      {"swap_eyes", r.decision.swap_eyes},
      {"rule", std::string(to_string(r.decision.rule))},
      {"width", info.width},
      {"height", info.height},
      {"fps", info.fps},
      {"duration_s", optional_number(info.duration_s)},
      {"video_codec", info.video_codec},
      {"audio_streams", info.audio_streams},
      {"container", info.container},
      {"display_aspect", info.display_aspect},
      {"sample_aspect_ratio", fmt::format("{}:{}", info.sar_num, info.sar_den)},
      {"rotation_degrees", info.rotation_degrees},
      {"frame_count", info.frame_count ? nlohmann::json(*info.frame_count) : nlohmann::json(nullptr)},
      {"pixel_format", info.pixel_format},
      {"bits_per_component", info.bits_per_component},
      {"color_matrix", std::string(to_string(info.matrix))},
      {"color_range", std::string(to_string(info.range))},
      {"stereo_metadata", r.metadata ? nlohmann::json{{"type", std::string(to_string(r.metadata->packing))},
                                                      {"inverted", r.metadata->inverted}}
                                     : nlohmann::json(nullptr)},
  };
  fmt::print("{}\n", out.dump());
}

void print_summary(const ProbeResult& r) {
  const VideoInfo& info = r.info;
  fmt::print("file:      {}\n", info.path);
  fmt::print("container: {}\n", info.container);
  fmt::print("video:     {} {}x{}, SAR {}:{}, display aspect {:.3f}, {} fps\n", info.video_codec, info.width,
             info.height, info.sar_num, info.sar_den, info.display_aspect,
             info.fps > 0.0 ? fmt::format("{:.3f}", info.fps) : std::string("unknown"));
  fmt::print("colour:    {} {}-bit, {} matrix{}, {} range\n", info.pixel_format, info.bits_per_component,
             to_string(info.matrix), info.matrix_tagged ? "" : " (untagged: default for the height)",
             to_string(info.range));
  if (info.rotation_degrees != 0) fmt::print("rotation:  {} degrees clockwise (applied)\n", info.rotation_degrees);
  fmt::print("duration:  {}{}\n", info.duration_s ? fmt::format("{:.3f} s", *info.duration_s) : "unknown",
             info.frame_count ? fmt::format(" ({} frames)", *info.frame_count) : "");
  fmt::print("audio:     {} stream{}\n", info.audio_streams, info.audio_streams == 1 ? "" : "s");
  if (r.metadata)
    fmt::print("stereo:    {}{} (file metadata)\n", to_string(r.metadata->packing),
               r.metadata->inverted ? ", right view first" : "");
  fmt::print("layout:    {}{} (rule: {})\n", to_string(r.decision.layout), r.decision.swap_eyes ? ", eyes swapped" : "",
             to_string(r.decision.rule));
}

}  // namespace

void add_probe_command(CLI::App& app) {
  auto options = std::make_shared<ProbeOptions>();
  auto* cmd = app.add_subcommand("probe", "Show what nelf sees in a media file and which stereo layout it would use");
  cmd->add_option("input", options->input, "Video file")->required();
  cmd->add_option("--layout", options->layout, "Stereo layout, overriding detection")
      ->check(CLI::IsMember({"sbs", "sbs-half", "tab", "tab-half", "fp", "alt", "mono"}));
  cmd->add_flag("--swap-eyes", options->swap_eyes, "Swap left and right (on top of what was detected)");
  cmd->add_flag("--json", options->json, "Print one JSON object instead of the summary");
  cmd->add_flag("--allow-network", options->allow_network,
                "Let FFmpeg use network protocols (off: only local files and pipes)");
  add_max_pixels_option(*cmd, options->max_pixels);
  cmd->callback([options] {
    ProbeResult result;
    try {
      result = probe(*options);
    } catch (const VideoError& e) {
      throw UserError(e.what());
    } catch (const UnsupportedStereoMetadata& e) {
      throw UserError(fmt::format("{}: {}", options->input, e.what()));
    }
    if (!result.decision.warning.empty()) fmt::print(stderr, "nelf: warning: {}\n", printable(result.decision.warning));
    if (result.stats.problems() > 0)
      fmt::print(stderr, "nelf: warning: {}: {} decode problem(s) in the first frames (damaged file?)\n",
                 printable(options->input), result.stats.problems());
    if (options->json)
      print_json(result);
    else
      print_summary(result);
  });
}

}  // namespace nelf::app
