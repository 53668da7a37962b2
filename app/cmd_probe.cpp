// `nelf probe IN`: what nelf sees in a media file — size, rate, codec, colour — and which stereo
// layout it would use, with the detection rule that decided (DESIGN.md §6).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "core/printable.hpp"
#include "inputs/media_streams.hpp"
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
  MediaStreams streams;
};

ProbeResult probe(const ProbeOptions& options) {
  quiet_ffmpeg_logs(true);
  // A live input has no file to describe: play and convert print what they read of it.
  SourceRequest request;
  request.input = options.input;
  if (const std::string driver(source_driver_for(request).name);
      driver == "x11" || driver == "device" || driver == "pipewire" || driver == "glx-stereo")
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

  ProbeResult result{source.info(), source.stereo_metadata(), {}, source.stats(), {}};
  LayoutEvidence evidence;
  if (!options.layout.empty()) evidence.flag = parse_stereo_layout(options.layout);  // checked by CLI11
  evidence.swap_eyes = options.swap_eyes;
  evidence.metadata = result.metadata;
  evidence.width = result.info.width;
  evidence.height = result.info.height;
  evidence.display_aspect = result.info.display_aspect;
  evidence.filename = options.input;
  evidence.multiview = result.info.multiview;
  result.decision = detect_stereo_layout(evidence);
  // FFmpeg sees an MPO's first JPEG only: its layout is the one play and convert read, the two
  // images of the file (the still reader's, which says why it chose it).
  if (is_mpo_name(options.input)) {
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
  result.streams = describe_media_streams(options.input, options.allow_network);
  return result;
}

nlohmann::json optional_number(const std::optional<double>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

nlohmann::json stereo_json(const std::optional<StereoMetadata>& metadata) {
  return metadata
             ? nlohmann::json{{"type", std::string(to_string(metadata->packing))}, {"inverted", metadata->inverted}}
             : nlohmann::json(nullptr);
}

nlohmann::json multiview_json(Multiview multiview) {
  return multiview == Multiview::none ? nlohmann::json(nullptr) : nlohmann::json(std::string(to_string(multiview)));
}

nlohmann::json stream_json(const MediaStream& s) {
  nlohmann::json out = {{"index", s.index},
                        {"type", s.type},
                        {"codec", s.codec},
                        {"profile", s.profile.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.profile)},
                        {"language", s.language.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.language)},
                        {"title", s.title.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.title)},
                        {"default", s.is_default},
                        {"forced", s.forced},
                        {"hearing_impaired", s.hearing_impaired},
                        {"visual_impaired", s.visual_impaired}};
  if (s.type == "video") {
    out["width"] = s.width;
    out["height"] = s.height;
    out["fps"] = s.fps;
    out["pixel_format"] = s.pixel_format;
    out["cover_art"] = s.cover_art;
    out["stereo_metadata"] = stereo_json(s.stereo);
    out["multiview"] = multiview_json(s.multiview);
  } else if (s.type == "audio") {
    out["channels"] = s.channels;
    out["channel_layout"] = s.channel_layout;
    out["sample_rate"] = s.sample_rate;
  } else if (s.type == "attachment") {
    out["filename"] = s.filename;
    out["mimetype"] = s.mimetype;
  }
  return out;
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
      {"stereo_metadata", stereo_json(r.metadata)},
      {"multiview", multiview_json(r.info.multiview)},
  };
  nlohmann::json streams = nlohmann::json::array(), chapters = nlohmann::json::array();
  for (const MediaStream& s : r.streams.streams) streams.push_back(stream_json(s));
  for (const MediaChapter& c : r.streams.chapters)
    chapters.push_back({{"id", c.id},
                        {"start_s", c.start_s},
                        {"end_s", c.end_s},
                        {"title", c.title.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.title)}});
  out["streams"] = std::move(streams);
  out["chapters"] = std::move(chapters);
  fmt::print("{}\n", out.dump());
}

// One stream as a player's track list shows it: "#1 audio ac3 5.1(side), 48000 Hz [eng] "Surround
// 5.1" (default)".
std::string stream_line(const MediaStream& s) {
  std::string line = fmt::format("#{} {} {}", s.index, s.type, s.codec);
  if (!s.profile.empty()) line += fmt::format(" ({})", s.profile);
  if (s.type == "video") {
    line += fmt::format(" {}x{}", s.width, s.height);
    if (s.fps > 0.0) line += fmt::format(", {:.3f} fps", s.fps);
    if (!s.pixel_format.empty()) line += ", " + s.pixel_format;
    if (s.stereo)
      line += fmt::format(", stereo {}{}", to_string(s.stereo->packing), s.stereo->inverted ? " right first" : "");
    if (s.multiview != Multiview::none) line += fmt::format(", {}", to_string(s.multiview));
  } else if (s.type == "audio") {
    line += fmt::format(" {}, {} Hz", s.channel_layout, s.sample_rate);
  } else if (s.type == "attachment") {
    line += fmt::format(" {}{}", s.filename, s.mimetype.empty() ? "" : " (" + s.mimetype + ")");
  }
  if (!s.language.empty()) line += fmt::format(" [{}]", s.language);
  if (!s.title.empty()) line += fmt::format(" \"{}\"", s.title);
  std::vector<std::string> flags;
  if (s.is_default) flags.emplace_back("default");
  if (s.forced) flags.emplace_back("forced");
  if (s.hearing_impaired) flags.emplace_back("hearing impaired");
  if (s.visual_impaired) flags.emplace_back("visual impaired");
  if (s.cover_art) flags.emplace_back("cover art");
  if (!flags.empty()) line += fmt::format(" ({})", fmt::join(flags, ", "));
  return line;
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
  if (r.info.multiview != Multiview::none)
    fmt::print("multiview: {} (FFmpeg decodes only the base view: 2D)\n", to_string(r.info.multiview));
  fmt::print("layout:    {}{} (rule: {})\n", to_string(r.decision.layout), r.decision.swap_eyes ? ", eyes swapped" : "",
             to_string(r.decision.rule));
  fmt::print("streams:\n");
  for (const MediaStream& s : r.streams.streams) fmt::print("  {}\n", printable(stream_line(s)));
  if (!r.streams.chapters.empty()) fmt::print("chapters:\n");
  for (const MediaChapter& c : r.streams.chapters)
    fmt::print("  {:>9.3f} - {:>9.3f} s  {}\n", c.start_s, c.end_s, printable(c.title));
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
