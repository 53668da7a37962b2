// `nelf convert IN OUT`: one still stereo image in, the packed output frame (elemental images for
// both eyes, per the signal) out as an image file.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <memory>
#include <optional>
#include <string>

#include <unistd.h>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include "app/commands.hpp"
#include "compositor/frame_compositor.hpp"
#include "compositor/overlays/subtitle_overlay.hpp"
#include "core/printable.hpp"
#include "hmz_output/frame_sink.hpp"
#include "hmz_output/image_sink.hpp"
#include "hmz_output/packing.hpp"
#include "hmz_output/signal.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/stereo_layout.hpp"
#include "inputs/stereo_matcher.hpp"
#include "inputs/video_source.hpp"
#include "optics/profile.hpp"
#include "player/convert_video.hpp"
#include "player/input_files.hpp"

namespace nelf::app {
namespace {

struct ConvertArgs : CommonArgs {
  std::string output;
  int bits = 8;
  bool overwrite = false;
  // Video only.
  std::optional<std::string> codec;  // unset: h264
  std::optional<int> crf;
  std::optional<double> start, duration;
  std::optional<long> frames;
  bool no_audio = false, quiet = false, strict = false;
  bool burn_subs = false;
  std::string sub_file;
  std::optional<std::string> sub_parallax;
  std::string sub_stereo;
  std::string sid = "auto";
  std::vector<std::string> slang;
};

// Inputs the still driver reads (OpenImageIO) become one image; everything else (and `synthetic:`)
// is video.
bool is_still_image(const std::string& input) {
  SourceRequest request;
  request.input = input;
  return source_driver_for(request).name == "still";
}

// Everything that can be checked without reading the input, checked before any work.
struct ConvertPlan {
  Profile profile;
  Signal signal;
  SourceRequest still;
  CompositorOptions compositor;
  ImageWriteOptions write;
};

ConvertPlan plan_convert(const ConvertArgs& args) {
  ConvertPlan plan;
  CommonOptions common = parse_common_options(args, true);
  plan.still.input = args.input;
  plan.still.right = args.right;
  plan.still.layout = common.layout;
  plan.still.swap_eyes = args.swap_eyes;
  plan.still.max_pixels = args.max_pixels;
  plan.still.quiet = true;  // a still is converted without a line about it (warnings are printed)
  plan.compositor = common.compositor;
  plan.profile = std::move(common.profile);
  plan.signal = common.signal;

  plan.write.overwrite = args.overwrite;
  plan.write.bits = args.bits;
  if (is_raw_output(args.output)) return plan;  // stdout: nothing to check
  try {
    check_image_writable(args.output, plan.write);
  } catch (const ImageWriteError& e) {
    throw UserError(e.what(), 1);
  }
  return plan;
}

// `-` (raw RGBA on stdout) has no codec, bit depth, sound or file to replace: options that would do
// nothing are refused rather than ignored, and a terminal is not fed binary.
void refuse_options_raw_cannot_apply(const ConvertArgs& args) {
  const auto refuse = [](const std::string& option) {
    throw UserError(fmt::format("{} does not apply to - (raw 8-bit RGBA frames on stdout)", option), 2);
  };
  if (args.codec) refuse("--codec");
  if (args.crf) refuse("--crf");
  if (args.bits != 8) refuse("--bits");
  if (::isatty(STDOUT_FILENO) == 1)
    throw UserError(
        "-: stdout is a terminal; raw video is for a pipe (e.g. nelf convert IN - | ffplay -f rawvideo "
        "-pixel_format rgba -video_size WxH -)",
        2);
}

// A still to `-`: its one packed frame, as the raw sink writes a video's.
void write_packed_still_raw(const StereoPair& views, const ConvertPlan& plan) {
  const Image packed = packed_still(views, plan.profile, plan.signal, plan.compositor);
  PackedFrame frame{packed.width(), packed.height(), 8, {}, 0.0};
  frame.rgba.resize(static_cast<std::size_t>(packed.width()) * packed.height() * 4);
  const float* in = packed.data();
  for (std::size_t i = 0; i < frame.rgba.size(); ++i)
    frame.rgba[i] = static_cast<std::uint8_t>(std::lround(std::clamp(in[i], 0.f, 1.f) * 255.f));
  const auto sink = open_raw_frame_sink(STDOUT_FILENO, frame.width, frame.height, 1.0);
  sink->write(frame);
  sink->finish();
}

void run_convert_video(const ConvertArgs& args, const InputFiles& inputs) {
  VideoConvertRequest r;
  r.inputs = inputs;
  r.input = args.input;
  r.right = args.right;
  r.output = args.output;
  CommonOptions common = parse_common_options(args, false);
  r.layout = common.layout;
  if (!args.right.empty()) r.layout = StereoLayout::pair;  // --right alone means a pair
  r.swap_eyes = args.swap_eyes;
  r.compositor = common.compositor;
  r.profile = std::move(common.profile);
  r.signal = common.signal;
  // 8 bits plays everywhere (10-bit sources are dithered to it); --bits 10 keeps 10, as HEVC Main 10
  // unless --codec says otherwise. Image files take 8 or 16.
  const bool image_output = is_image_sequence_pattern(args.output) || is_image_file_name(args.output);
  if (!is_raw_output(args.output)) {
    if (image_output && args.bits != 8 && args.bits != 16)
      throw UserError(fmt::format("--bits {}: 8 or 16 for {}", args.bits, args.output), 2);
    if (!image_output && args.bits != 8 && args.bits != 10)
      throw UserError(fmt::format("--bits {}: 8 (plays everywhere) or 10 (HEVC Main 10) for a video file", args.bits),
                      2);
  }
  r.encoder.bits = args.bits;
  r.encoder.codec = args.codec.value_or(args.bits == 10 && !image_output ? "hevc" : "h264");
  r.encoder.crf = args.crf;
  r.encoder.overwrite = args.overwrite;
  r.encoder.audio = !args.no_audio;
  if (args.crf && (*args.crf < 0 || *args.crf > 51))
    throw UserError(fmt::format("--crf must be 0..51, got {}", *args.crf), 2);
  if (args.start && *args.start < 0) throw UserError(fmt::format("--start must be >= 0, got {}", *args.start), 2);
  if (args.duration && *args.duration <= 0)
    throw UserError(fmt::format("--duration must be > 0, got {}", *args.duration), 2);
  if (args.frames && *args.frames <= 0) throw UserError(fmt::format("--frames must be > 0, got {}", *args.frames), 2);
  r.start_s = args.start;
  r.duration_s = args.duration;
  r.max_frames = args.frames;
  // One image named as such (x.png) is the frame at --start, as `ffmpeg -ss T -i IN -frames:v 1 x.png`
  // writes it; more frames need a name for each.
  if (!is_image_sequence_pattern(args.output) && is_image_file_name(args.output)) {
    const std::filesystem::path out(args.output);
    const std::string pattern =
        (out.parent_path() / (out.stem().string() + "_%05d" + out.extension().string())).string();
    if (args.frames && *args.frames > 1)
      throw UserError(fmt::format("{} holds one frame; for {} frames name an image sequence such as {}", args.output,
                                  *args.frames, pattern),
                      2);
    if (args.duration)
      throw UserError(
          fmt::format("{} holds one frame; for --duration name an image sequence such as {}", args.output, pattern), 2);
    r.max_frames = 1;
  }
  if (!args.burn_subs && !args.sub_file.empty()) throw UserError("--sub-file needs --burn-subs", 2);
  if (!args.burn_subs && args.sub_parallax) throw UserError("--sub-parallax needs --burn-subs", 2);
  if (!args.burn_subs && !args.sub_stereo.empty()) throw UserError("--sub-stereo needs --burn-subs", 2);
  if (!args.burn_subs && (args.sid != "auto" || !args.slang.empty()))
    throw UserError("--sid and --slang choose the track --burn-subs draws", 2);
  if (args.sid == "no") throw UserError("--sid no: leave out --burn-subs to draw no subtitles", 2);
  if (args.burn_subs) {
    r.burn_subs = SubtitleBurn{args.sub_file,
                               parse_sub_parallax(args.sub_parallax),
                               {parse_track_number(args.sid, "--sid"), args.slang},
                               parse_sub_stereo(args.sub_stereo)};
  }
  r.quiet = args.quiet;
  r.strict = args.strict;
  r.allow_network = args.allow_network;
  r.max_pixels = args.max_pixels;
  r.device_options = parse_device_options(args, {args.input});
  if (is_raw_output(args.output)) {
    refuse_options_raw_cannot_apply(args);
    if (!args.quiet) quiet_ffmpeg_logs(true);
    return convert_video(r);
  }
  const std::filesystem::path out(args.output);
  const auto dir = out.parent_path().empty() ? std::filesystem::path(".") : out.parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw UserError(fmt::format("{}: cannot write: directory {} does not exist", args.output, dir.string()), 1);
  // symlink_status: a dangling symlink is an existing name too (replacing it needs -y, as for stills).
  if (!is_image_sequence_pattern(args.output) && std::filesystem::exists(std::filesystem::symlink_status(out, ec)) &&
      !args.overwrite)
    throw UserError(fmt::format("{}: already exists; pass -y to overwrite", args.output), 1);
  if (!args.quiet) quiet_ffmpeg_logs(true);
  convert_video(r);
}

void run_convert(const ConvertArgs& args) {
  quiet_ffmpeg_logs(true);
  // Before anything else, -y included: no output over what is being read.
  InputFiles inputs;
  inputs.add(args.input, "the input");
  inputs.add(args.right, "the --right view");
  inputs.add(args.profile, "the --profile");
  inputs.add(args.sub_file, "the --sub-file");
  if (!is_raw_output(args.output)) inputs.refuse_as_output(args.output);
  if (!is_still_image(args.input)) return run_convert_video(args, inputs);
  if (args.burn_subs)
    throw UserError(fmt::format("{}: --burn-subs is for video; a still has no subtitles", args.input), 2);
  if (is_raw_output(args.output)) refuse_options_raw_cannot_apply(args);
  const ConvertPlan plan = plan_convert(args);
  // Read as play reads it (the still driver); composed from its float views, not the frame's bytes.
  const std::optional<StereoVideoFrame> frame = open_source(plan.still)->next();
  if (!frame || !frame->exact_views) throw std::logic_error("the still driver gave no views of " + args.input);
  const StereoPair& views = *frame->exact_views;
  if (is_raw_output(args.output)) return write_packed_still_raw(views, plan);
  write_packed_still(views, plan.profile, plan.signal, plan.compositor, args.output, plan.write);
}

}  // namespace

double parse_number(std::string_view text, bool& ok) {
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  ok = ec == std::errc() && end == text.data() + text.size() && std::isfinite(value);
  return value;
}

std::optional<int> parse_track_number(const std::string& value, const std::string& option) {
  if (value == "auto" || value == "no") return std::nullopt;
  int number = 0;
  const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), number);
  if (error != std::errc() || end != value.data() + value.size() || number < 1)
    throw UserError(fmt::format("{} {}: a track number from 1, auto or no", option, printable(value)), 2);
  return number;
}

SubtitleStereo parse_sub_stereo(const std::string& value) {
  if (value.empty()) return SubtitleStereo::flat;
  if (value == "sbs") return SubtitleStereo::side_by_side;
  if (value == "tab") return SubtitleStereo::top_bottom;
  throw UserError(fmt::format("--sub-stereo {}: sbs or tab (the subtitle pictures hold both eyes side by side or top "
                              "and bottom)",
                              printable(value)),
                  2);
}

SubtitleDepth parse_sub_parallax(const std::optional<std::string>& parallax) {
  constexpr double kMax = max_sub_parallax_percent;
  if (!parallax) return {};
  if (*parallax == "auto") return {true, auto_sub_margin_percent};
  bool ok = false;
  const double value = parse_number(*parallax, ok);
  if (!ok || std::abs(value) > kMax)
    throw UserError(fmt::format("--sub-parallax must be -{0}..{0} (percent of the view width) or auto, got {1}", kMax,
                                printable(*parallax)),
                    2);
  return {false, value};
}

Signal resolve_signal(const Profile& profile, const std::string& name) {
  const std::string signal_name = name.empty() ? profile.signal : name;
  const auto signal = find_signal(signal_name);
  if (!signal) {
    const std::string source =
        name.empty() ? fmt::format(" (output.signal of profile {})", profile.name) : std::string();
    throw UserError(fmt::format("unknown signal '{}'{} (use {})", signal_name, source, fmt::join(signal_names(), ", ")),
                    2);
  }
  return *signal;
}

Image packed_still(const StereoPair& views, const Profile& profile, const Signal& signal,
                   const CompositorOptions& options) {
  FrameCompositor compositor(profile, options, packed_layout(signal, profile.display.resolution));
  // A still knows no depth of its own: --depth auto and estimate both estimate it from its views.
  const bool with_depth = options.depth != DepthMode::off && profile.lens_array;
  return compositor.render_still(views, with_depth ? estimate_still_disparity(views) : nullptr);
}

void write_packed_still(const StereoPair& views, const Profile& profile, const Signal& signal,
                        const CompositorOptions& options, const std::string& output, const ImageWriteOptions& write) {
  const Image frame = packed_still(views, profile, signal, options);
  try {
    write_image_file(frame, output, write);
  } catch (const ImageWriteError& e) {
    throw UserError(e.what(), 1);
  }
}

std::optional<StereoLayout> parse_layout_option(const std::string& name) {
  if (name == "auto") return std::nullopt;
  const auto layout = parse_stereo_layout(name);
  if (!layout)
    throw UserError(fmt::format("unknown layout '{}' (use auto, {})", name, fmt::join(stereo_layout_names(), ", ")), 2);
  return layout;
}

CommonOptions parse_common_options(const CommonArgs& args, bool still) {
  CommonOptions common;
  common.layout = parse_layout_option(args.layout);
  if (common.layout) {
    if (still && *common.layout == StereoLayout::alt)
      throw UserError("layout alt (frame-sequential) needs a video; a still holds one view per frame", 2);
    if (*common.layout == StereoLayout::pair && args.right.empty())
      throw UserError("layout pair needs the right view as a second file (--right FILE)", 2);
  }
  if (!args.right.empty() && common.layout && *common.layout != StereoLayout::pair)
    throw UserError(fmt::format("--right gives the right view as a second file; layout {} does not apply", args.layout),
                    2);
  try {
    validate_fsaa(args.fsaa);
  } catch (const std::invalid_argument& e) {
    throw UserError(e.what(), 2);
  }
  common.compositor.fsaa = args.fsaa;
  common.compositor.depth = parse_depth_option(args.depth);
  common.compositor.gpu = args.gpu;
  common.compositor.defect_compensation = !args.no_defect_compensation;

  common.profile = load_profile(args.profile);  // ProfileError -> status 2 in main()
  common.signal = resolve_signal(common.profile, args.signal);
  return common;
}

void refuse_gpu_for_live_output(const std::optional<int>& gpu, const std::string& command) {
  if (!gpu) return;
  throw UserError(fmt::format("--gpu picks the GPU of headless rendering (convert, simulate, calibrate --output FILE); "
                              "{} renders on its display's GPU (--output kms: NELF_DRM_DEVICE picks the card)",
                              command),
                  2);
}

void add_input_option(CLI::App& cmd, CommonArgs& args) {
  cmd.add_option("input", args.input,
                 "Stereo image or video (side-by-side, top-bottom, frame-packed, JPS, MPO, ...), or a live window "
                 "(x11:window=TITLE)")
      ->required();
}

void add_common_options(CLI::App& cmd, CommonArgs& args, bool with_input) {
  if (with_input) add_input_option(cmd, args);
  cmd.add_option("--profile", args.profile, "Device profile: built-in name or TOML file")->capture_default_str();
  cmd.add_option("--layout", args.layout,
                 fmt::format("Stereo layout of the input: auto, {}", fmt::join(stereo_layout_names(), ", ")))
      ->capture_default_str();
  cmd.add_option("--right", args.right, "The right view as a separate file (layout pair)");
  cmd.add_flag("--swap-eyes", args.swap_eyes, "The source stores the right view first");
  cmd.add_option(
      "--signal", args.signal,
      fmt::format("Output signal: {} (default: the profile's output.signal)", fmt::join(signal_names(), ", ")));
  cmd.add_option("--fsaa", args.fsaa, "Antialiasing: 0 (one tap), 1 (prefilter), 4 or 16 (sub-samples)")
      ->capture_default_str();
  cmd.add_option("--gpu", args.gpu,
                 "EGL device index to render on (default: NELF_GPU, else the first GPU, else software)");
  cmd.add_flag("--allow-network", args.allow_network,
               "Let FFmpeg use network protocols (default: files and pipes only)");
  add_depth_option(cmd, args.depth);
  add_defect_compensation_option(cmd, args.no_defect_compensation);
  add_max_pixels_option(cmd, args.max_pixels);
  cmd.add_option("--device-option", args.device_options,
                 "For a capture device (v4l2:, device:): one of its options as KEY=VALUE, as ffmpeg takes it before "
                 "-i (video_size=1920x1080, input_format=mjpeg, framerate=60); repeatable");
}

std::vector<std::pair<std::string, std::string>> parse_device_options(const CommonArgs& args,
                                                                      const std::vector<std::string>& inputs) {
  std::vector<std::pair<std::string, std::string>> options;
  if (args.device_options.empty()) return options;
  for (const std::string& input : inputs)
    if (input.rfind("v4l2:", 0) != 0 && input.rfind("device:", 0) != 0)
      throw UserError(fmt::format("--device-option is for capture devices (v4l2:/dev/videoN, device:FORMAT:INPUT), "
                                  "not {}",
                                  printable(input)),
                      2);
  for (const std::string& option : args.device_options) {
    const std::size_t equals = option.find('=');
    if (equals == 0 || equals == std::string::npos)
      throw UserError(fmt::format("--device-option {}: KEY=VALUE, e.g. video_size=1920x1080", printable(option)), 2);
    options.emplace_back(option.substr(0, equals), option.substr(equals + 1));
  }
  return options;
}

void add_depth_option(CLI::App& cmd, std::string& depth) {
  cmd.add_option("--depth", depth,
                 "Composite with the content's depth: off (everything on the flat emulated screen), auto (the depth "
                 "the input knows, as the synthetic scenes do, else estimated from the two views), estimate (always "
                 "estimated from the two views)")
      ->capture_default_str();
}

DepthMode parse_depth_option(const std::string& depth) {
  const std::optional<DepthMode> mode = parse_depth_mode(depth);
  if (!mode)
    throw UserError(fmt::format("--depth must be one of {}, got '{}'", fmt::join(depth_mode_names(), ", "), depth), 2);
  return *mode;
}

void add_defect_compensation_option(CLI::App& cmd, bool& no_defect_compensation) {
  cmd.add_flag("--no-defect-compensation", no_defect_compensation,
               "Show the dead and stuck pixels of the profile's defect map as they are (default: hidden by "
               "their ray bundles)");
}

void add_max_pixels_option(CLI::App& cmd, std::int64_t& max_pixels) {
  cmd.add_option("--max-pixels", max_pixels,
                 "Refuse images and video frames of more pixels than this, before decoding them")
      // Up to 16384x16384: no image or frame may be larger than 16384 a side anyway.
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{16384} * 16384))
      ->capture_default_str();
}

void add_convert_command(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  auto* cmd =
      app.add_subcommand("convert", "Convert a stereo image or video (or synthetic:) into what the display needs");
  add_common_options(*cmd, *args);
  cmd->add_option("output", args->output,
                  "Output: a video file, an image (.png, .tif, .exr, .jpg; of a video: the frame at --start) or an "
                  "image sequence pattern (frames_%05d.png)")
      ->required();
  cmd->add_option("--bits", args->bits,
                  "Bits per channel of the output file: 8 (the default; 10-bit video is dithered to it), 10 for a "
                  "video file (HEVC Main 10 unless --codec says otherwise), or 16 for .png/.tif")
      ->capture_default_str();
  cmd->add_flag("-y,--overwrite", args->overwrite, "Replace the output file if it exists");
  cmd->add_option("--codec", args->codec, "Video: h264 (default), hevc, ffv1 or any FFmpeg video encoder");
  cmd->add_option("--crf", args->crf, "Video: quality for h264/hevc (0 best .. 51; default 18)");
  cmd->add_option("--start", args->start, "Video: start at this time (seconds)");
  cmd->add_option("--duration", args->duration, "Video: convert this many seconds");
  cmd->add_option("--frames", args->frames, "Video: convert at most this many frames");
  cmd->add_flag("--no-audio", args->no_audio, "Video: leave the audio out");
  cmd->add_flag("--quiet", args->quiet, "Video: no progress output (warnings are still printed)");
  cmd->add_flag("--strict", args->strict, "Video: a damaged or truncated input is an error");
  cmd->add_flag("--burn-subs", args->burn_subs,
                "Video: draw subtitles into both eyes (--sub-file, else INPUT.srt/.ass/.vtt beside the input, else "
                "the input's first subtitle track)");
  cmd->add_option("--sub-file", args->sub_file,
                  "Video, with --burn-subs: the subtitle file (SRT, ASS/SSA, WebVTT, PGS .sup, VobSub .idx, ...)");
  cmd->add_option("--sub-parallax", args->sub_parallax,
                  "Video, with --burn-subs: the subtitles' depth in percent of the view width (positive = in front "
                  "of the screen; default 0, on it), or auto: just in front of the picture beneath them");
  cmd->add_option("--sub-stereo", args->sub_stereo,
                  "Video, with --burn-subs: bitmap subtitles (PGS, DVB, VobSub) authored per eye, sbs (left eye's in "
                  "the left half) or tab (left eye's on top)");
  cmd->add_option("--sid", args->sid,
                  "Video, with --burn-subs: the subtitle track by number (1 = the file's first subtitle stream, or "
                  "--sub-file's), or auto")
      ->capture_default_str();
  cmd->add_option("--slang", args->slang,
                  "Video, with --burn-subs: the subtitle track by language, first match wins: eng,ger")
      ->delimiter(',');
  cmd->callback([args] { run_convert(*args); });
}

}  // namespace nelf::app
