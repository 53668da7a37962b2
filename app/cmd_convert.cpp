// `nelf convert IN OUT`: one still stereo image in, the packed output frame (elemental images for
// both eyes, per the signal) out as an image file.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <memory>
#include <optional>
#include <string>

#include "app/commands.hpp"
#include "compositor/make_compositor.hpp"
#include "compositor/profile.hpp"
#include "hmz_output/image_sink.hpp"
#include "hmz_output/packing.hpp"
#include "hmz_output/signal.hpp"
#include "inputs/stereo_layout.hpp"
#include "inputs/still_source.hpp"

namespace nelf::app {
namespace {

struct ConvertArgs {
  std::string input;
  std::string output;
  std::string profile = "hmz-t1";
  std::string layout = "auto";
  std::string right;
  bool swap_eyes = false;
  std::string signal;  // empty = the profile's output.signal
  int fsaa = 1;
  std::optional<int> gpu;
  int bits = 8;
  bool overwrite = false;
};

// Everything that can be checked without reading the input, checked before any work.
struct ConvertPlan {
  Profile profile;
  Signal signal;
  StillOptions still;
  CompositorOptions compositor;
  ImageWriteOptions write;
};

ConvertPlan plan_convert(const ConvertArgs& args) {
  ConvertPlan plan;
  if (args.layout != "auto") {
    const auto layout = parse_stereo_layout(args.layout);
    if (!layout)
      throw UserError(
          fmt::format("unknown layout '{}' (use auto, {})", args.layout, fmt::join(stereo_layout_names(), ", ")), 2);
    if (*layout == StereoLayout::alt)
      throw UserError("layout alt (frame-sequential) needs a video; a still holds one view per frame", 2);
    if (*layout == StereoLayout::pair && args.right.empty())
      throw UserError("layout pair needs the right view as a second file (--right FILE)", 2);
    if (!args.right.empty() && *layout != StereoLayout::pair)
      throw UserError(
          fmt::format("--right gives the right view as a second file; layout {} does not apply", args.layout), 2);
    plan.still.layout = layout;
  }
  if (!args.right.empty()) plan.still.right = args.right;
  plan.still.swap_eyes = args.swap_eyes;

  try {
    validate_fsaa(args.fsaa);
  } catch (const std::invalid_argument& e) {
    throw UserError(e.what(), 2);
  }
  plan.compositor.fsaa = args.fsaa;
  plan.compositor.gpu = args.gpu;

  plan.profile = load_profile(args.profile);  // ProfileError -> status 2 in main()
  const std::string signal_name = args.signal.empty() ? plan.profile.signal : args.signal;
  const auto signal = find_signal(signal_name);
  if (!signal) {
    const std::string source =
        args.signal.empty() ? fmt::format(" (output.signal of profile {})", plan.profile.name) : std::string();
    throw UserError(fmt::format("unknown signal '{}'{} (use {})", signal_name, source, fmt::join(signal_names(), ", ")),
                    2);
  }
  plan.signal = *signal;

  plan.write.overwrite = args.overwrite;
  plan.write.bits = args.bits;
  try {
    check_image_writable(args.output, plan.write);
  } catch (const ImageWriteError& e) {
    throw UserError(e.what(), 1);
  }
  return plan;
}

void run_convert(const ConvertArgs& args) {
  const ConvertPlan plan = plan_convert(args);
  StillStereo still;
  try {
    still = load_still(args.input, plan.still);
  } catch (const StillError& e) {
    throw UserError(e.what(), 1);
  }
  if (!still.decision.warning.empty()) fmt::print(stderr, "nelf: warning: {}\n", still.decision.warning);

  const auto compositor = make_compositor(plan.profile, plan.compositor);
  const EyeImages eyes = compositor->compose(still.views);
  const Image frame = pack_eyes(plan.signal, eyes);
  try {
    write_image_file(frame, args.output, plan.write);
  } catch (const ImageWriteError& e) {
    throw UserError(e.what(), 1);
  }
}

}  // namespace

void add_convert_command(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  auto* cmd = app.add_subcommand("convert", "Convert a stereo still image into the display's output frame");
  cmd->add_option("input", args->input, "Stereo image (side-by-side, top-bottom, frame-packed, JPS, MPO, ...)")
      ->required();
  cmd->add_option("output", args->output, "Output image (.png, .tif, .exr, .jpg)")->required();
  cmd->add_option("--profile", args->profile, "Device profile: built-in name or TOML file")->capture_default_str();
  cmd->add_option("--layout", args->layout,
                  fmt::format("Stereo layout of the input: auto, {}", fmt::join(stereo_layout_names(), ", ")))
      ->capture_default_str();
  cmd->add_option("--right", args->right, "The right view as a separate image (layout pair)");
  cmd->add_flag("--swap-eyes", args->swap_eyes, "The source stores the right view first");
  cmd->add_option(
      "--signal", args->signal,
      fmt::format("Output signal: {} (default: the profile's output.signal)", fmt::join(signal_names(), ", ")));
  cmd->add_option("--fsaa", args->fsaa, "Antialiasing: 0 (one tap), 1 (prefilter), 4 or 16 (sub-samples)")
      ->capture_default_str();
  cmd->add_option("--gpu", args->gpu,
                  "EGL device index to render on (default: NELF_GPU, else the first GPU, else software)");
  cmd->add_option("--bits", args->bits, "Bits per channel of the output file: 8, or 16 for .png/.tif")
      ->capture_default_str();
  cmd->add_flag("-y,--overwrite", args->overwrite, "Replace the output file if it exists");
  cmd->callback([args] { run_convert(*args); });
}

}  // namespace nelf::app
