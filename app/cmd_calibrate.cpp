// `nelf calibrate`: test patterns drawn through the compositor, with keys that tune the profile's
// calibration live (player/calibration_controls) and --save to keep the result; or, with
// --pattern and an image file as --output, the packed pattern frame written headless like a still
// converted by `nelf convert`. With --defects: flat fields on the panels without the lens mapping,
// keys that mark dead and stuck pixels, and the defect map saved beside the profile; or, with an
// image file as --output, the packed flat field written headless.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "app/commands.hpp"
#include "hmz_output/display.hpp"
#include "hmz_output/display_drivers.hpp"
#include "hmz_output/image_sink.hpp"
#include "hmz_output/packing.hpp"
#include "inputs/test_patterns.hpp"
#include "optics/profile.hpp"
#include "player/calibrate_session.hpp"
#include "player/calibration_controls.hpp"
#include "player/defect_marking.hpp"
#include "player/input_files.hpp"

namespace nelf::app {
namespace {

struct CalibrateArgs {
  std::string profile = "hmz-t1";
  std::string output = "window";
  std::string save;
  std::string monitor;
  std::string connector;
  std::string pattern;
  std::string signal;
  int fsaa = 1;
  std::optional<int> gpu;
  bool overwrite = false;
  bool no_defect_compensation = false;
  bool defects = false;
  std::string field;
  bool fsaa_given = false;  // --fsaa on the command line (it has a default)
};

bool is_live_output(const std::string& name) { return find_display_driver(name) != nullptr; }

TestPattern parse_pattern_option(const std::string& name) {
  const auto pattern = parse_test_pattern(name);
  if (!pattern)
    throw UserError(fmt::format("unknown pattern '{}' (use {})", name, fmt::join(test_pattern_names(), ", ")), 2);
  return *pattern;
}

CompositorOptions compositor_options(const CalibrateArgs& args) {
  try {
    validate_fsaa(args.fsaa);
  } catch (const std::invalid_argument& e) {
    throw UserError(e.what(), 2);
  }
  CompositorOptions options;
  options.fsaa = args.fsaa;
  options.gpu = args.gpu;
  options.defect_compensation = !args.no_defect_compensation;
  return options;
}

StereoPair pattern_views(TestPattern pattern, const Profile& profile) {
  try {
    return make_test_pattern(pattern, pattern_geometry(profile));
  } catch (const TestPatternError& e) {
    throw UserError(fmt::format("pattern {}: {}", test_pattern_name(pattern), e.what()), 2);
  }
}

// The image --output's write options, the file checked writable before anything is composited
// (status 1 when it is not).
ImageWriteOptions checked_image_output(const CalibrateArgs& args) {
  ImageWriteOptions write;
  write.overwrite = args.overwrite;
  try {
    check_image_writable(args.output, write);
  } catch (const ImageWriteError& e) {
    throw UserError(e.what(), 1);
  }
  return write;
}

// Headless: the packed frame of one pattern as an image file.
void write_pattern_image(const CalibrateArgs& args) {
  if (args.pattern.empty())
    throw UserError(fmt::format("--output {} is an image file: give the pattern to write with --pattern {}",
                                args.output, fmt::join(test_pattern_names(), "|")),
                    2);
  if (!args.save.empty())
    throw UserError(
        fmt::format("--save keeps what the keys adjusted and needs a window (--output {}), not an image file",
                    display_driver_names()),
        2);
  InputFiles inputs;
  inputs.add(args.profile, "the --profile");
  inputs.refuse_as_output(args.output);
  const TestPattern pattern = parse_pattern_option(args.pattern);
  const CompositorOptions options = compositor_options(args);
  const Profile profile = load_profile(args.profile);  // ProfileError -> status 2 in main()
  const Signal signal = resolve_signal(profile, args.signal);
  const ImageWriteOptions write = checked_image_output(args);
  write_packed_still(pattern_views(pattern, profile), profile, signal, options, args.output, write);
}

// --defects: which options go with it. The flat field is the panel's own pixels, so the options
// of the lens mapping's patterns do not apply; --field names the first field and means nothing
// without --defects.
std::optional<DefectField> defect_mode(const CalibrateArgs& args) {
  if (!args.defects) {
    if (!args.field.empty())
      throw UserError(fmt::format("--field {} is the flat field of --defects: add --defects", args.field), 2);
    return std::nullopt;
  }
  if (!args.pattern.empty())
    throw UserError(fmt::format("--defects shows flat fields, not --pattern {}: leave one out", args.pattern), 2);
  if (args.fsaa_given)
    throw UserError("--fsaa antialiases the lens mapping, which --defects does not use: leave it out", 2);
  if (args.field.empty()) return DefectField::black;
  const auto field = parse_defect_field(args.field);
  if (!field)
    throw UserError(fmt::format("unknown field '{}' (use {})", args.field, fmt::join(defect_field_names(), ", ")), 2);
  return field;
}

// Headless --defects: the packed frame of the flat field, the profile's known defects ringed as
// the live panels show them (no cursor, no status line).
void write_defect_field_image(const CalibrateArgs& args, DefectField field) {
  if (!args.save.empty())
    throw UserError(fmt::format("--save keeps what the keys marked and needs a window (--output {}), not an image file",
                                display_driver_names()),
                    2);
  InputFiles inputs;
  inputs.add(args.profile, "the --profile");
  inputs.refuse_as_output(args.output);
  const Profile profile = load_profile(args.profile);  // ProfileError -> status 2 in main()
  const Signal signal = resolve_signal(profile, args.signal);
  const ImageWriteOptions write = checked_image_output(args);
  const DefectMap known = profile.correction.defects ? *profile.correction.defects : DefectMap{};
  const EyeImages panels = {DefectMarking::field_image(profile.display.resolution, field, known, Eye::left),
                            DefectMarking::field_image(profile.display.resolution, field, known, Eye::right)};
  try {
    write_image_file(place_eyes(packed_layout(signal, profile.display.resolution), panels), args.output, write);
  } catch (const ImageWriteError& e) {
    throw UserError(e.what(), 1);
  }
}

// --save must be writable before the user spends time calibrating.
void check_save_path(const std::string& path) {
  if (path.empty()) return;
  const std::filesystem::path p(path);
  const auto dir = p.parent_path().empty() ? std::filesystem::path(".") : p.parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw UserError(fmt::format("--save {}: directory {} does not exist", path, dir.string()), 1);
  if (std::filesystem::is_directory(p, ec)) throw UserError(fmt::format("--save {}: is a directory", path), 1);
  if (p.extension() != ".toml")
    throw UserError(fmt::format("--save {}: a profile is a .toml file (e.g. my-hmz.toml)", path), 2);
}

// A map beside --save that the profile does not name is someone's earlier work (or another
// file): --defects would replace it with the marks of this session, so it is refused before
// anything is shown.
void check_defect_map_target(const Profile& profile, const std::string& save) {
  const DefectMapSave where = defect_map_save(profile, save);
  std::error_code ec;
  if (profile.correction.defect_map_path.empty() && !where.map.empty() && std::filesystem::exists(where.map, ec))
    throw UserError(fmt::format("--save {}: {} exists and the profile names no defect map; to continue it, set "
                                "correction.defect_map = \"{}\" in the profile, else move it away",
                                save, where.map.string(), where.map.filename().string()),
                    2);
}

void run_calibrate(const CalibrateArgs& args) {
  const std::optional<DefectField> defects = defect_mode(args);
  if (!is_live_output(args.output))
    return defects ? write_defect_field_image(args, *defects) : write_pattern_image(args);
  if (args.output != "offscreen") refuse_gpu_for_live_output(args.gpu, "a live calibration");
  CalibrateSession session;
  session.output = args.output;
  session.gpu = args.gpu;
  session.pattern = args.pattern.empty() ? TestPattern::stripes : parse_pattern_option(args.pattern);
  session.defects = defects;
  session.compositor = compositor_options(args);
  session.profile = load_profile(args.profile);  // ProfileError -> status 2 in main()
  session.signal = resolve_signal(session.profile, args.signal);
  check_save_path(args.save);
  if (defects) check_defect_map_target(session.profile, args.save);
  session.save = args.save;
  session.monitor = args.monitor;
  session.connector = args.connector;
  run_calibrate_session(session);
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  auto* cmd = app.add_subcommand(
      "calibrate",
      "Tune a profile to your eyes with test patterns and keys (h for help), or write a pattern image; "
      "--defects marks dead and stuck pixels");
  cmd->add_option("--profile", args->profile, "Device profile to start from: built-in name or TOML file")
      ->capture_default_str();
  cmd->add_option("--output", args->output,
                  fmt::format("{}; or an image file (.png, .tif, .exr, .jpg) for --pattern", display_driver_help()))
      ->capture_default_str();
  cmd->add_option("--monitor", args->monitor,
                  "fullscreen: the monitor whose name contains this (default: one containing \"HMZ\")");
  cmd->add_option("--connector", args->connector,
                  "kms: the connector, e.g. HDMI-A-1 (default: the first with a 3D frame-packing mode)");
  cmd->add_option("--save", args->save, "Write the adjusted profile to this .toml file (w, and when quitting)");
  cmd->add_option("--pattern", args->pattern,
                  fmt::format("Pattern: {} (the first one shown; required with an image --output)",
                              fmt::join(test_pattern_names(), ", ")));
  cmd->add_option(
      "--signal", args->signal,
      fmt::format("Output signal: {} (default: the profile's output.signal)", fmt::join(signal_names(), ", ")));
  auto* fsaa =
      cmd->add_option("--fsaa", args->fsaa, "Antialiasing: 0, 1, 4 or 16 (as for convert)")->capture_default_str();
  cmd->add_option("--gpu", args->gpu,
                  "EGL device index (image output only; a live output renders on its display's GPU)");
  cmd->add_flag("--defects", args->defects,
                "Find dead and stuck pixels: flat fields on the panels without the lens mapping, marked with keys "
                "(h for help), the map saved beside the profile (its correction.defect_map, else FILE.defects "
                "beside --save FILE.toml)");
  cmd->add_option("--field", args->field,
                  "With --defects: the flat field shown first, or written to an image --output (default black)")
      ->check(CLI::IsMember(defect_field_names()));
  cmd->add_flag("-y,--overwrite", args->overwrite, "Replace the image --output if it exists");
  add_defect_compensation_option(*cmd, args->no_defect_compensation);
  cmd->callback([args, fsaa] {
    args->fsaa_given = fsaa->count() > 0;
    run_calibrate(*args);
  });
}

}  // namespace nelf::app
