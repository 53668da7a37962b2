// `nelf simulate`: what an eye sees on the display (DESIGN.md §5). Composites a still for one eye,
// traces a thin-lens eye through the lens array onto it, and compares with the same eye looking at
// the emulated screen, or with the real scene when the source knows its depth (issue #15): retinal
// image, ideal image, PSNR (per region of known depth too), and optionally a PSNR sweep over screen
// distance × accommodation (the analogue of Lanman & Luebke's Fig. 11) and a focus sweep that finds
// where the eye focuses best on each region.
#include <fmt/format.h>
#include <unistd.h>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <system_error>

#include <fmt/ranges.h>
#include "analysis/comfort_zone.hpp"
#include "analysis/defect_visibility.hpp"
#include "analysis/eye_simulator.hpp"
#include "analysis/focus_sweep.hpp"
#include "app/commands.hpp"
#include "app/heatmap.hpp"
#include "compositor/make_compositor.hpp"
#include "compositor/reference.hpp"
#include "core/printable.hpp"
#include "hmz_output/image_sink.hpp"
#include "inputs/glx_stereo_source.hpp"
#include "inputs/source_drivers.hpp"
#include "inputs/stereo_matcher.hpp"
#include "inputs/still_source.hpp"
#include "inputs/synthetic_source.hpp"
#include "optics/defect_compensation.hpp"
#include "optics/mapping.hpp"
#include "player/input_files.hpp"

namespace nelf::app {

namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();

// The compositing step: what the display shows for `eye`, rendered the way `nelf convert` renders it
// (the GL compositor at the default antialiasing), with the content's depth when given.
Image composite_eye_image(const Profile& profile, Eye eye, const View& view,
                          std::shared_ptr<const DisparitySurface> depth = nullptr) {
  const auto compositor = make_compositor(profile, CompositorOptions{});
  compositor->set_depth(eye, std::move(depth));
  EyeImages eyes = compositor->compose({view, view});
  return std::move(eyes[static_cast<int>(eye)]);
}

// What the panel shows for `eye`: the composite of the profile without its defect map (the map is
// taken out so that the defects, and their compensation, are applied once here, whatever the
// compositor does with a map), then, for a panel with a map, the panel's defects over that
// composite and over the compensated one. The sweep and the single simulation show the same panel.
struct PanelImages {
  Image clean;                       // a defect-free panel
  Image uncompensated, compensated;  // with the defects (only for a profile with a map)
  std::optional<EyeDefectPlan> plan;
  bool compensation = false;  // whether the panel shows the compensated composite
  const Image& shown() const { return !plan ? clean : compensation ? compensated : uncompensated; }
};

PanelImages panel_images(const Profile& profile, Eye eye, const View& view, const EyeMapping& rendering,
                         double pupil_mm, bool compensation, std::shared_ptr<const DisparitySurface> depth = nullptr) {
  Profile without_defects = profile;
  without_defects.correction.defects.reset();
  without_defects.correction.defect_map.clear();
  without_defects.correction.defect_map_path.clear();
  PanelImages panel;
  panel.compensation = compensation;
  panel.clean = composite_eye_image(without_defects, eye, view, std::move(depth));
  if (const DefectMap* defects = profile.correction.defects.get()) {
    DefectPlanOptions plan_options;
    plan_options.pupil_mm = pupil_mm;
    panel.plan = plan_defect_compensation(rendering, *defects, plan_options);
    panel.uncompensated = defective_display(*defects, eye, panel.clean);
    if (compensation)
      panel.compensated = defective_display(*defects, eye, compensated_display(*panel.plan, panel.clean));
  }
  return panel;
}

struct SimulateArgs {
  std::string input;
  std::string profile = "hmz-t1";
  std::string eye = "left";
  std::optional<std::string> focus;
  std::optional<double> pupil_mm;
  std::string eye_offset = "0,0";
  std::string output;
  std::string ideal;
  std::string sweep;
  std::string focus_sweep;
  std::string depth = "off";
  std::string reference = "auto";
  bool json = false;
  bool no_defect_compensation = false;
  std::string layout = "auto";
  std::string right;
  bool swap_eyes = false;
  std::int64_t max_pixels = kDefaultMaxPixels;
};

Vec2 parse_eye_offset(const std::string& text) {
  const auto comma = text.find(',');
  bool ok_x = false, ok_y = false;
  Vec2 offset;
  if (comma != std::string::npos) {
    offset.x = parse_number(std::string_view(text).substr(0, comma), ok_x);
    offset.y = parse_number(std::string_view(text).substr(comma + 1), ok_y);
  }
  if (!ok_x || !ok_y)
    throw UserError(
        fmt::format("--eye-offset-mm must be two numbers in millimetres as X,Y (e.g. 1.5,-0.5), got '{}'", text), 2);
  return offset;
}

// "inf" (or "infinity") is the relaxed eye; anything else must be a positive number of millimetres.
double parse_focus_mm(const std::string& text) {
  if (text == "inf" || text == "infinity") return infinity;
  bool ok = false;
  const double value = parse_number(text, ok);
  if (!ok || value <= 0.0)
    throw UserError(fmt::format("--focus-mm must be a distance > 0 in millimetres or 'inf', got '{}'", text), 2);
  return value;
}

// Fails early, before minutes of work, when an output cannot be created in its directory.
void check_writable(const std::string& path, const char* option) {
  if (path.empty()) return;
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec) || ::access(dir.c_str(), W_OK) != 0)
    throw UserError(fmt::format("cannot write {} '{}': directory '{}' does not exist or is not writable", option, path,
                                dir.string()));
  if (std::filesystem::is_directory(path, ec))
    throw UserError(fmt::format("cannot write {} '{}': it is a directory", option, path));
}

std::string distance_label(double mm) {
  if (!std::isfinite(mm)) return "inf";
  return mm >= 1000.0 ? fmt::format("{:g} m", mm / 1000.0) : fmt::format("{:.0f} mm", mm);
}

// The input as simulate sees it: this eye's view, both views (what depth is estimated from), and
// what the source knows of its scene (the synthetic scenes' exact depth and regions).
struct SimulatedInput {
  StereoPair pair;
  std::shared_ptr<const StereoDisparity> known_depth;
  std::vector<SceneRegion> regions;
  std::string warning;
  const View& view(Eye eye) const { return eye == Eye::left ? pair.left : pair.right; }
};

// An RGBA8 view of a frame as simulate's float image.
View frame_view(const std::vector<std::uint8_t>& rgba, int width, int height, double aspect) {
  View view;
  view.image = Image(width, height);
  float* out = view.image.data();
  for (std::size_t i = 0; i < rgba.size(); ++i) out[i] = rgba[i] / 255.0f;
  view.display_aspect = aspect;
  return view;
}

// A quad-buffer game's frame (glx-stereo:, the game started with nelf's interposer), as it plays:
// `want_depth`, the first frame whose depth buffers gave its disparity (the relation to the views
// takes a frame or a few), within 120 frames; otherwise, or failing that, the frame at hand.
SimulatedInput load_game_frame(const SimulateArgs& args, bool want_depth) {
  SourceRequest request;
  request.input = args.input;
  request.swap_eyes = args.swap_eyes;
  request.known_depth = want_depth;
  request.quiet = args.json;
  const std::unique_ptr<Source> source = open_source(request);
  std::optional<StereoVideoFrame> frame;
  for (int i = 0; i < 120; ++i) {
    std::optional<StereoVideoFrame> next = source->next();
    if (!next) break;
    frame = std::move(next);
    if (!want_depth || frame->disparity) break;
  }
  if (!frame) throw UserError(fmt::format("{}: the game ended before it showed a frame", printable(args.input)));
  if (frame->bits != 8 || frame->block != std::array<int, 2>{1, 1})
    throw UserError(fmt::format("{}: the game's frame came in a form simulate does not read", printable(args.input)));
  SimulatedInput in;
  in.pair.left = frame_view(frame->left, frame->width, frame->height, frame->aspect);
  in.pair.right = frame_view(frame->right, frame->width, frame->height, frame->aspect);
  in.known_depth = frame->disparity;
  return in;
}

SimulatedInput load_simulated_input(const SimulateArgs& args, const StillOptions& still, const Profile& profile) {
  // Its depth always, as a synthetic scene's: the real scene to compare with, even on the flat screen.
  if (is_glx_stereo_spec(args.input)) return load_game_frame(args, true);
  SimulatedInput in;
  if (is_synthetic_spec(args.input)) {
    // The built-in clip's first frame, filmed for this display's emulated screen so that the depth
    // it knows is the depth the eye sees: lets the demo show what the eye sees without any media file.
    try {
      const SyntheticClip clip(matched_to_display(parse_synthetic_spec(args.input), profile));
      in.pair = clip.render(0);
      in.known_depth = clip.disparity(0);
      in.regions = clip.regions(0);
    } catch (const std::invalid_argument& e) {
      throw UserError(e.what(), 2);
    }
    return in;
  }
  try {
    StillStereo stereo = load_still(args.input, still);
    in.warning = stereo.decision.warning;
    in.pair = std::move(stereo.views);
  } catch (const StillError& e) {
    throw UserError(e.what());
  }
  return in;
}

// The heatmap of a sweep's gain beside its table: TABLE.gain.png.
std::filesystem::path gain_heatmap_path(const std::string& csv_path) {
  return std::filesystem::path(csv_path).replace_extension(".gain.png");
}

// A sweep's heatmap (beside the table, as .png; `gain` as .gain.png) and then its table: a failure
// leaves none of them half-written.
void write_sweep(const Heatmap& map, const std::string& csv, const std::filesystem::path& csv_path, const char* what,
                 const Heatmap* gain = nullptr) {
  write_heatmap_png(map, std::filesystem::path(csv_path).replace_extension(".png"));
  if (gain) write_heatmap_png(*gain, gain_heatmap_path(csv_path));
  try {
    write_file_atomically(csv_path, true, [&](const std::filesystem::path& temporary) {
      std::ofstream out(temporary, std::ios::binary);
      out << csv;
      out.close();
      if (!out) throw UserError(fmt::format("cannot write {} '{}'", what, csv_path.string()));
    });
  } catch (const ImageWriteError& e) {
    throw UserError(e.what());
  }
}

// The depth the composite follows (--depth): the source's own where it knows it (auto), else the
// stereo matcher's estimate (null when the pair cannot be matched); none when off.
std::shared_ptr<const StereoDisparity> composite_depth_of(DepthMode mode, const SimulatedInput& input) {
  if (mode == DepthMode::off) return nullptr;
  if (mode == DepthMode::automatic && input.known_depth) return input.known_depth;
  return estimate_still_disparity(input.pair);
}

std::shared_ptr<const DisparitySurface> eye_surface(Eye eye, const std::shared_ptr<const StereoDisparity>& d) {
  return d ? std::make_shared<const DisparitySurface>(eye == Eye::left ? d->left : d->right) : nullptr;
}

// What the sweep composites and compares with, as the single simulation does (--depth, --reference).
struct SweepSetUp {
  const SimulatedInput& input;
  const StillOptions& still;
  DepthMode depth_mode;
  std::shared_ptr<const StereoDisparity> still_depth;  // a still's (its disparities do not change with the screen)
  bool scene_reference;
};

// PSNR over screen distance × accommodation, both in diopters (0 D = infinity for accommodation).
// Affordable on two cores: 1.5 retinal samples per display footprint and 5×5 pupil samples (the single
// simulation uses 3 and 7×7); each screen distance is composited once. A synthetic scene is filmed
// again for each screen distance, so that every row shows the same real scene (its depths in
// millimetres fixed, its disparities those of that screen); against it (--reference scene) the rows
// show what following the content's depth gains over the flat screen: with --depth, each cell is
// also simulated on the flat screen and the gain has a heatmap of its own. Each row marks the focus
// that is comfortable while the eyes converge on the screen (Shibata et al.'s zone of comfort).
void run_sweep(const SimulateArgs& args, const Profile& profile, Eye eye, const SweepSetUp& set_up,
               const EyeModel& base_eye, const std::filesystem::path& csv_path) {
  const std::vector<double> screen_diopters{4.0, 3.5, 3.0, 2.5, 2.0, 1.5, 1.0, 0.5, 0.25};  // rows, near at top
  constexpr double accommodation_step = 0.25;
  std::vector<double> accommodation_diopters;
  for (int k = 0; k <= 16; ++k) accommodation_diopters.push_back(accommodation_step * k);
  SimulatorOptions options;
  options.samples_per_footprint = 1.5;
  EyeModel sweep_eye = base_eye;
  sweep_eye.pupil_samples_per_axis = 5;
  const bool refilmed = is_synthetic_spec(args.input);

  Heatmap map;
  map.title = fmt::format("PSNR of the {} eye vs. {}: {}, depth {}, pupil {:g} mm", args.eye,
                          set_up.scene_reference ? "the real scene" : "a real screen at the row's distance",
                          profile.name, depth_mode_name(set_up.depth_mode), base_eye.pupil_mm);
  map.x_label = "accommodation (diopters, 0 = infinity)";
  map.y_label = "screen distance";
  map.value_label = "PSNR dB";
  map.note = "red: zone of comfort for the eyes converged on the screen (Shibata et al. 2011)";
  map.lines.resize(2);
  HeatmapLine &far_end = map.lines[0], &near_end = map.lines[1];
  for (double a : accommodation_diopters) map.x_ticks.push_back(fmt::format("{:g}", a));
  std::string csv =
      "screen_diopters,screen_mm,accommodation_diopters,accommodation_mm,psnr_db,psnr_full_screen_db,"
      "comfort_zone,psnr_flat_db,gain_db\n";
  const bool with_depth = set_up.depth_mode != DepthMode::off;
  Heatmap gain = map;
  gain.title = fmt::format(
      "Gain of depth {} over the flat screen vs. {}: {}, {} eye, pupil {:g} mm", depth_mode_name(set_up.depth_mode),
      set_up.scene_reference ? "the real scene" : "a real screen", profile.name, args.eye, base_eye.pupil_mm);
  gain.value_label = "gain dB";
  gain.value_decimals = 1;
  for (double screen_d : screen_diopters) {
    const double screen_mm = 1000.0 / screen_d;
    Profile at_distance = profile;
    at_distance.screen.distance_mm = screen_mm;
    std::optional<SimulatedInput> refilmed_input;
    if (refilmed) refilmed_input = load_simulated_input(args, set_up.still, at_distance);
    const SimulatedInput& input = refilmed ? *refilmed_input : set_up.input;
    const View& view = input.view(eye);
    const EyeMapping rendering = make_eye_mapping(at_distance, eye, view.aspect());
    const std::shared_ptr<const StereoDisparity> depth =
        refilmed ? composite_depth_of(set_up.depth_mode, input) : set_up.still_depth;
    const std::optional<SceneDepth> scene =
        set_up.scene_reference ? std::optional<SceneDepth>(SceneDepth{eye_surface(eye, input.known_depth),
                                                                      depth_geometry(at_distance, rendering)})
                               : std::nullopt;
    // The panel's defects (and their compensation, planned for this distance) are in every row.
    const PanelImages panel = panel_images(at_distance, eye, view, rendering, base_eye.pupil_mm,
                                           !args.no_defect_compensation, eye_surface(eye, depth));
    const Image& displayed = panel.shown();
    // The same panel on the flat screen, for the gain (the depth-aware one itself where there is no depth).
    std::optional<PanelImages> flat_panel;
    if (depth)
      flat_panel = panel_images(at_distance, eye, view, rendering, base_eye.pupil_mm, !args.no_defect_compensation);
    const EyeSimulator simulator(device_optics(at_distance, eye), rendering, view.image, options);
    map.y_ticks.push_back(fmt::format("{:g} D ({})", screen_d, distance_label(rendering.render_distance_mm)));
    const AccommodationRange comfortable = comfortable_accommodation(1000.0 / rendering.render_distance_mm);
    far_end.column_position.push_back(comfortable.farthest_diopters / accommodation_step);
    near_end.column_position.push_back(comfortable.nearest_diopters / accommodation_step);
    auto& row = map.values.emplace_back();
    auto& gain_row = gain.values.emplace_back();
    for (double accommodation_d : accommodation_diopters) {
      sweep_eye.focus_mm = accommodation_d > 0.0 ? 1000.0 / accommodation_d : infinity;
      const SimulationResult r = simulator.simulate(displayed, sweep_eye, scene ? &*scene : nullptr);
      const double flat_db = flat_panel
                                 ? simulator.simulate(flat_panel->shown(), sweep_eye, scene ? &*scene : nullptr).psnr_db
                                 : r.psnr_db;
      row.push_back(r.psnr_db);
      gain_row.push_back(r.psnr_db - flat_db);
      csv += fmt::format(
          "{:g},{:.1f},{:g},{},{:.3f},{:.3f},{},{:.3f},{:.3f}\n", screen_d, rendering.render_distance_mm,
          accommodation_d,
          std::isfinite(sweep_eye.focus_mm) ? fmt::format("{:.1f}", sweep_eye.focus_mm) : std::string("inf"), r.psnr_db,
          r.psnr_full_screen_db, comfortable.contains(accommodation_d) ? 1 : 0, flat_db, r.psnr_db - flat_db);
    }
  }
  gain.y_ticks = map.y_ticks;
  gain.lines = map.lines;

  write_sweep(map, csv, csv_path, "sweep", with_depth ? &gain : nullptr);
}

// The focus sweep as a table (one row per accommodation and region) and a heatmap beside it (one
// row per region).
void write_focus_sweep(const FocusSweep& focus, const SimulateArgs& args, const Profile& profile, double pupil_mm,
                       bool scene_reference, const std::filesystem::path& csv_path) {
  Heatmap map;
  map.title = fmt::format("PSNR of the {} eye vs. the all-in-focus {}: {}, depth {}, pupil {:g} mm", args.eye,
                          scene_reference ? "scene" : "screen", profile.name, args.depth, pupil_mm);
  map.x_label = "accommodation (diopters, 0 = infinity)";
  map.y_label = "region (its depth)";
  map.value_label = "PSNR dB";
  for (double a : focus.accommodation_diopters) map.x_ticks.push_back(fmt::format("{:g}", a));
  std::string csv = "region,depth_mm,accommodation_diopters,accommodation_mm,psnr_db\n";
  for (const FocusCurve& c : focus.regions) {
    map.y_ticks.push_back(std::isfinite(c.depth_mm) ? fmt::format("{} ({:.2f} D; best {:.2f} D)", c.name,
                                                                  1000.0 / c.depth_mm, c.best_focus_diopters)
                                                    : fmt::format("{} (best {:.2f} D)", c.name, c.best_focus_diopters));
    map.values.push_back(c.psnr_db);
    for (std::size_t k = 0; k < focus.accommodation_diopters.size(); ++k) {
      const double a = focus.accommodation_diopters[k];
      csv += fmt::format("{},{},{:g},{},{:.3f}\n", c.name,
                         std::isfinite(c.depth_mm) ? fmt::format("{:.1f}", c.depth_mm) : std::string(), a,
                         a > 0.0 ? fmt::format("{:.1f}", 1000.0 / a) : std::string("inf"), c.psnr_db[k]);
    }
  }
  write_sweep(map, csv, csv_path, "focus sweep");
}

void run_simulate(const SimulateArgs& args) {
  // Arguments first: a typo should not cost a compositing pass.
  const Eye eye = args.eye == "right" ? Eye::right : Eye::left;
  const DepthMode depth_mode = parse_depth_option(args.depth);
  const std::string& reference = args.reference;
  EyeModel eye_model;
  eye_model.offset_mm = parse_eye_offset(args.eye_offset);
  std::optional<double> focus_mm;
  if (args.focus) focus_mm = parse_focus_mm(*args.focus);
  if (args.pupil_mm && !(*args.pupil_mm > 0.0))
    throw UserError(fmt::format("--pupil-mm must be > 0, got {}", *args.pupil_mm), 2);
  for (const auto& [option, path] : {std::pair{"--sweep", &args.sweep}, std::pair{"--focus-sweep", &args.focus_sweep}})
    if (!path->empty() && std::filesystem::path(*path).extension() == ".png")
      throw UserError(fmt::format("{} '{}' is the CSV table; the heatmap goes beside it as .png", option, *path), 2);
  InputFiles inputs;
  inputs.add(args.input, "the input");
  inputs.add(args.right, "the --right view");
  inputs.add(args.profile, "the --profile");
  for (const std::string& output : {args.output, args.ideal, args.sweep, args.focus_sweep})
    if (!output.empty()) inputs.refuse_as_output(output);
  for (const std::string& table : {args.sweep, args.focus_sweep})
    if (!table.empty()) inputs.refuse_as_output(std::filesystem::path(table).replace_extension(".png").string());
  if (!args.sweep.empty()) inputs.refuse_as_output(gain_heatmap_path(args.sweep).string());
  check_writable(args.output, "--output");
  check_writable(args.ideal, "--ideal");
  check_writable(args.sweep, "--sweep");
  check_writable(args.focus_sweep, "--focus-sweep");
  StillOptions still;
  still.layout = parse_layout_option(args.layout);
  if (!args.right.empty()) still.right = args.right;
  still.swap_eyes = args.swap_eyes;
  still.max_pixels = args.max_pixels;
  try {
    check_image_writable(args.output, {true, 8});
    if (!args.ideal.empty()) check_image_writable(args.ideal, {true, 8});
  } catch (const ImageWriteError& e) {
    throw UserError(e.what());
  }

  const Profile profile = load_profile(args.profile);
  const DeviceOptics device = device_optics(profile, eye);  // a stock profile fails here, before any work
  eye_model.pupil_mm = args.pupil_mm.value_or(profile.viewing.pupil_mm);
  eye_model.focus_mm = focus_mm.value_or(render_distance_mm(profile));

  // The source's view for this eye (a stereo still in any layout; a 2D image is the view of both).
  const SimulatedInput input = load_simulated_input(args, still, profile);
  if (!input.warning.empty() && !args.json) fmt::print(stderr, "nelf: warning: {}\n", printable(input.warning));
  const View& view = input.view(eye);
  const EyeMapping rendering = make_eye_mapping(profile, eye, view.aspect());
  const DepthGeometry geometry = depth_geometry(profile, rendering);

  // The depth the composite follows; none leaves everything on the flat screen.
  const std::shared_ptr<const StereoDisparity> composite_depth = composite_depth_of(depth_mode, input);
  const std::string depth_used = !composite_depth ? "none"
                                 : composite_depth == input.known_depth
                                     ? (input.known_depth->origin == DisparityOrigin::game ? "game" : "known")
                                     : "estimated";
  if (depth_mode != DepthMode::off && !composite_depth && !args.json)
    fmt::print(stderr,
               "nelf: depth: the stereo pair cannot be matched (too little texture); simulating the flat screen\n");
  // What the retina is compared with (--reference): the real scene where the source knows it.
  const bool scene_reference = reference == "scene" || (reference == "auto" && input.known_depth);
  if (scene_reference && !input.known_depth)
    throw UserError(
        "--reference scene needs an input that knows its depth (synthetic:, e.g. synthetic:scene=planes); use "
        "--reference screen",
        2);
  const std::optional<SceneDepth> scene =
      scene_reference ? std::optional<SceneDepth>(SceneDepth{eye_surface(eye, input.known_depth), geometry})
                      : std::nullopt;
  const SceneDepth* scene_ptr = scene ? &*scene : nullptr;
  // A panel with a defect map shows its defects, compensated unless asked not to; the retina and the
  // PSNR are of what it shows.
  const PanelImages panel = panel_images(profile, eye, view, rendering, eye_model.pupil_mm,
                                         !args.no_defect_compensation, eye_surface(eye, composite_depth));
  const EyeSimulator simulator(device, rendering, view.image);
  const DefectMap* defects = profile.correction.defects.get();
  const Image& clean = panel.clean;
  const Image& uncompensated = panel.uncompensated;
  const std::optional<EyeDefectPlan>& plan = panel.plan;
  const Image& displayed = panel.shown();
  const SimulationResult result = simulator.simulate(displayed, eye_model, scene_ptr);

  // The regions of known depth as the retina sees them, each judged on its own.
  const auto retinal_regions = [&](const EyeSimulator& sim, const EyeModel& e) {
    std::vector<RetinalRegion> out;
    for (const SceneRegion& r : input.regions)
      out.push_back(
          {r.name, r.depth_mm, sim.view_region_mask(e, eye == Eye::left ? r.left_mask : r.right_mask, scene_ptr)});
    return out;
  };
  struct RegionResult {
    std::string name;
    double depth_mm;
    double psnr_db;
  };
  std::vector<RegionResult> region_results;
  for (RetinalRegion& r : retinal_regions(simulator, eye_model)) {
    std::size_t count = 0;
    for (std::size_t k = 0; k < r.mask.size(); ++k) count += r.mask[k] = r.mask[k] && result.evaluated[k] ? 1 : 0;
    region_results.push_back({r.name, r.depth_mm, count ? psnr_db(result.retina, result.ideal, r.mask) : std::nan("")});
  }

  // Where the eye focuses best on each region (the whole clear field for inputs without regions).
  std::optional<FocusSweep> focus;
  if (!args.focus_sweep.empty()) {
    SimulatorOptions options;
    options.samples_per_footprint = 1.5;  // as --sweep: 19 retinas in seconds, not minutes
    const EyeSimulator sweep_simulator(device, rendering, view.image, options);
    EyeModel sweep_eye = eye_model;
    sweep_eye.pupil_samples_per_axis = 5;
    std::vector<RetinalRegion> regions = retinal_regions(sweep_simulator, sweep_eye);
    if (regions.empty()) regions.push_back({"all", std::nan(""), sweep_simulator.on_screen_mask(sweep_eye)});
    try {
      focus = sweep_focus(sweep_simulator, displayed, sweep_eye, scene_ptr, regions, accommodation_steps(4.5, 0.25));
    } catch (const std::invalid_argument& e) {
      throw UserError(fmt::format("--focus-sweep: {}", e.what()));
    }
  }

  if (!args.sweep.empty())
    run_sweep(args, profile, eye, {input, still, depth_mode, composite_depth, scene_reference}, eye_model, args.sweep);
  if (focus) write_focus_sweep(*focus, args, profile, eye_model.pupil_mm, scene_reference, args.focus_sweep);
  try {
    write_image_file(result.retina, args.output, {true, 8});
    if (!args.ideal.empty()) write_image_file(result.ideal, args.ideal, {true, 8});
  } catch (const ImageWriteError& e) {
    throw UserError(e.what());
  }

  const auto finite_or_null = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  // The defects' visibility: the display as shown (and, when compensated, also without the
  // compensation) against the defect-free one.
  nlohmann::json defect_json;
  std::string defect_line;
  if (defects) {
    std::vector<PixelDefect> of_eye;
    for (const PixelDefect& d : defects->defects)
      if (d.eye == eye) of_eye.push_back(d);
    std::vector<const Image*> displays{&displayed};
    if (!args.no_defect_compensation) displays.push_back(&uncompensated);
    const auto visibility =
        measure_defect_visibility(simulator, rendering, of_eye, clean, displays, eye_model.pupil_mm);
    const auto spots = [](const DefectSpotFigures& f) {
      return nlohmann::json{{"count", f.count},
                            {"worst_spot_contrast", f.worst_spot_contrast},
                            {"mean_spot_contrast", f.mean_spot_contrast}};
    };
    const auto figures = [&](const DefectVisibility& v) {
      nlohmann::json j{{"measured", v.all.count},
                       {"worst_spot_contrast", v.all.worst_spot_contrast},
                       {"mean_spot_contrast", v.all.mean_spot_contrast},
                       {"defect_psnr_db", finite_or_null(v.defect_psnr_db)},
                       {"dead", spots(v.dead)},
                       {"stuck", spots(v.stuck)}};
      return j;
    };
    defect_json = figures(visibility[0]);
    defect_json["count"] = of_eye.size();
    defect_json["outside_lit"] = plan->outside_lit;
    defect_json["uncompensable"] = plan->uncompensable;
    defect_json["compensated"] = !args.no_defect_compensation;
    if (!args.no_defect_compensation) defect_json["uncompensated"] = figures(visibility[1]);
    defect_line = fmt::format(
        "{} defects ({} outside the lit elemental images, {} uncompensable), {}: worst spot contrast {:.2f}%, mean "
        "{:.2f}%, defect PSNR {:.2f} dB",
        of_eye.size(), plan->outside_lit, plan->uncompensable,
        args.no_defect_compensation ? "not compensated" : "compensated", 100 * visibility[0].all.worst_spot_contrast,
        100 * visibility[0].all.mean_spot_contrast, visibility[0].defect_psnr_db);
    if (!args.no_defect_compensation)
      defect_line += fmt::format(" (without compensation {:.2f}%, {:.2f}%, {:.2f} dB)",
                                 100 * visibility[1].all.worst_spot_contrast,
                                 100 * visibility[1].all.mean_spot_contrast, visibility[1].defect_psnr_db);
  }
  if (args.json) {
    nlohmann::json j;
    j["psnr_db"] = finite_or_null(result.psnr_db);
    j["focus_mm"] = finite_or_null(eye_model.focus_mm);  // null: relaxed eye, focused at infinity
    j["pupil_mm"] = eye_model.pupil_mm;
    j["eye"] = args.eye;
    j["eye_offset_mm"] = {eye_model.offset_mm.x, eye_model.offset_mm.y};
    j["psnr_full_screen_db"] = finite_or_null(result.psnr_full_screen_db);
    j["evaluated_fraction"] = result.evaluated_fraction;
    j["retina_size"] = {result.retina.width(), result.retina.height()};
    j["depth"] = depth_mode_name(depth_mode);
    j["depth_used"] = depth_used;  // none, known, game or estimated
    j["reference"] = scene_reference ? "scene" : "screen";
    if (!region_results.empty()) {
      j["regions"] = nlohmann::json::array();
      for (const RegionResult& r : region_results)
        j["regions"].push_back({{"name", r.name}, {"depth_mm", r.depth_mm}, {"psnr_db", finite_or_null(r.psnr_db)}});
    }
    if (focus) {
      j["focus_sweep"] = nlohmann::json::array();
      for (const FocusCurve& c : focus->regions)
        j["focus_sweep"].push_back({{"name", c.name},
                                    {"depth_mm", finite_or_null(c.depth_mm)},
                                    {"depth_diopters", finite_or_null(1000.0 / c.depth_mm)},
                                    {"best_focus_diopters", c.best_focus_diopters}});
    }
    if (defects) j["defects"] = defect_json;
    fmt::print("{}\n", j.dump());
  } else {
    fmt::print(
        "PSNR {:.2f} dB ({} eye focused at {}, pupil {:g} mm, offset {:g},{:g} mm; {:.0f}% of the screen in "
        "the clear field, {:.2f} dB over all of it)\n",
        result.psnr_db, args.eye, distance_label(eye_model.focus_mm), eye_model.pupil_mm, eye_model.offset_mm.x,
        eye_model.offset_mm.y, 100 * result.evaluated_fraction, result.psnr_full_screen_db);
    if (defects) fmt::print("{}\n", defect_line);
    fmt::print("against the {}; depth {}{}\n", scene_reference ? "real scene" : "emulated screen",
               depth_mode_name(depth_mode),
               depth_mode == DepthMode::off ? ""
               : depth_used == "none"       ? " (none to be had: the flat screen)"
                                            : fmt::format(" ({})", depth_used));
    for (const RegionResult& r : region_results)
      fmt::print("region {} at {}: PSNR {:.2f} dB\n", r.name, distance_label(r.depth_mm), r.psnr_db);
    if (focus)
      for (const FocusCurve& c : focus->regions)
        fmt::print("best focus on {}{}: {:.2f} D\n", c.name,
                   std::isfinite(c.depth_mm) ? fmt::format(" ({:.2f} D away)", 1000.0 / c.depth_mm) : "",
                   c.best_focus_diopters);
  }
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  auto* cmd = app.add_subcommand(
      "simulate",
      "Simulate an eye looking at the display: composite IN for one eye, trace a thin-lens eye through the lens "
      "array, write the retinal image and the PSNR against the same eye looking at the emulated screen");
  cmd->add_option("input", args->input,
                  "Stereo still image (any layout nelf convert reads; a 2D image is used for both eyes)")
      ->required();
  cmd->add_option("--layout", args->layout,
                  fmt::format("Stereo layout of the input: auto, {}", fmt::join(stereo_layout_names(), ", ")))
      ->capture_default_str();
  cmd->add_option("--right", args->right, "The right view as a separate image (layout pair)");
  cmd->add_flag("--swap-eyes", args->swap_eyes, "The source stores the right view first");
  add_max_pixels_option(*cmd, args->max_pixels);
  cmd->add_option("--profile", args->profile, "Device profile: built-in name or TOML file")->capture_default_str();
  cmd->add_option("--eye", args->eye, "Which eye")->check(CLI::IsMember({"left", "right"}))->capture_default_str();
  cmd->add_option("--focus-mm", args->focus,
                  "Accommodation distance from the pupil in mm, or 'inf' (default: the screen distance)");
  cmd->add_option("--pupil-mm", args->pupil_mm, "Pupil diameter (default: the profile's viewing.pupil_mm)");
  cmd->add_option("--eye-offset-mm", args->eye_offset, "Pupil displacement X,Y from the design position (mm)")
      ->capture_default_str();
  cmd->add_option("--output,-o", args->output, "Retinal image to write (PNG)")->required();
  cmd->add_option("--ideal", args->ideal, "Also write the ideal image (the eye looking at the screen)");
  cmd->add_flag("--no-defect-compensation", args->no_defect_compensation,
                "Show the profile's defect map uncompensated (the defects' figures then lack the comparison)");
  add_depth_option(*cmd, args->depth);
  cmd->add_option("--reference", args->reference,
                  "What the retina is compared with: the real scene (the planes at their depths; inputs that know "
                  "their depth only), the emulated screen, or auto (the scene where known)")
      ->check(CLI::IsMember({"auto", "screen", "scene"}))
      ->capture_default_str();
  cmd->add_option("--focus-sweep", args->focus_sweep,
                  "Also sweep the accommodation 0-4.5 D in 0.25 D steps and tabulate each region's PSNR against the "
                  "all-in-focus reference into this CSV, with a heatmap beside it (.png); prints where each region "
                  "is in best focus");
  cmd->add_flag("--json", args->json, "Print one JSON object: psnr_db, focus_mm (null = infinity), pupil_mm, ...");
  cmd->add_option("--sweep", args->sweep,
                  "Also tabulate PSNR over screen distance (0.25-4 D) x accommodation (0-4 D) into this CSV and draw "
                  "a heatmap beside it (.png) with the zone of comfort; composites with --depth and compares with "
                  "--reference as the single simulation does (a synthetic scene is filmed for each distance); uses "
                  "1.5 retinal samples per display pixel and 5x5 pupil samples");
  cmd->callback([args] { run_simulate(*args); });
}

}  // namespace nelf::app
