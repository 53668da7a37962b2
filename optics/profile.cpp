#include "optics/profile.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "core/embedded.hpp"
#include "optics/defect_map.hpp"
#include "optics/optics.hpp"

namespace nelf {

namespace {

// Every key the schema knows, as "table.key" (DESIGN.md §8). Tables are listed so that an unknown
// table name gets a suggestion too.
const std::vector<std::string>& known_keys() {
  static const std::vector<std::string> keys = {
      "name",
      "description",
      "display",
      "display.resolution",
      "display.pixel_pitch_mm",
      "display.size_mm",
      "lens_array",
      "lens_array.pitch_mm",
      "lens_array.focal_length_mm",
      "lens_array.gap_mm",
      "lens_array.rotation_deg",
      "lens_array.offset_mm",
      "magnifier",
      "magnifier.width_mm",
      "magnifier.focal_length_mm",
      "viewing",
      "viewing.eye_relief_mm",
      "viewing.virtual_image_mm",
      "viewing.pupil_mm",
      "viewing.ipd_mm",
      "screen",
      "screen.distance_mm",
      "screen.width_mm",
      "screen.converge",
      "output",
      "output.signal",
      "calibration",
      "calibration.left",
      "calibration.right",
      "calibration.left.shift_px",
      "calibration.left.rotation_deg",
      "calibration.left.pitch_scale",
      "calibration.right.shift_px",
      "calibration.right.rotation_deg",
      "calibration.right.pitch_scale",
      "correction",
      "correction.prescription_diopters",
      "correction.defect_map",
      "magnifier_comparison",
      "magnifier_comparison.eye_box_mm",
      "magnifier_comparison.f_number",
  };
  return keys;
}

const std::vector<std::string>& known_signals() {
  // The HDMI 1.4a frame-packed modes, and the plain layouts that follow the panel's size (for panels
  // larger than any frame-packed mode, such as the film prototypes: files and previews).
  static const std::vector<std::string> signals = {"hdmi-fp-720p60", "hdmi-fp-720p50", "hdmi-fp-1080p24", "sbs", "tab",
                                                   "left",           "right"};
  return signals;
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string nearest_known_key(const std::string& key) {
  std::string best;
  std::size_t best_distance = std::string::npos;
  for (const auto& k : known_keys()) {
    const auto d = edit_distance(key, k);
    if (d < best_distance) best_distance = d, best = k;
  }
  return best;
}

// The bounds of DESIGN.md §11 / docs/profiles.md "Limits": every length and every figure derived
// from a profile stays in a range where the optics mean something and every count fits an int.
// Shortest and longest length a profile may give (1 µm .. 1 km; a screen or image farther than a
// kilometre is at infinity for the eye, 0.001 D).
constexpr double kMinLengthMm = 0.001;
constexpr double kMaxLengthMm = 1e6;
// The finest pixel pitch: 0.1 µm, a fifth of the shortest visible wavelength; no panel comes near.
constexpr double kMinPixelPitchMm = 1e-4;
// The largest panel side: a display worn in front of the eye is not a metre wide.
constexpr double kMaxPanelMm = 1000.0;
// Each elemental image must span at least this many pixels per axis: with fewer a lens shows a
// single pixel, one ray, and there is no light field to speak of. This also bounds the lens count
// by half the panel's pixels (at most 8192 per axis).
constexpr double kMinElementalImagePx = 2.0;
// The calibration ranges of `nelf calibrate`'s keys.
constexpr double kMinPitchScale = 0.5, kMaxPitchScale = 2.0;
constexpr double kMaxFNumber = 100.0;

// Reads one profile, collecting the first problem as a ProfileError.
class Reader {
 public:
  Reader(const toml::table& root, std::string origin) : root_(root), origin_(std::move(origin)) {}

  [[noreturn]] void fail(const toml::node* node, const std::string& key, const std::string& message) const {
    std::string where = origin_;
    if (node && node->source().begin.line > 0) where += fmt::format(":{}", node->source().begin.line);
    throw ProfileError(fmt::format("{}: {} {}", where, key, message));
  }

  // The value as a message shows it: on one line (toml++ prints long arrays over several lines),
  // long arrays cut short. Control characters in strings are escaped where messages are printed.
  static std::string show(const toml::node& node) {
    std::ostringstream out;
    if (auto s = node.as_string()) {
      out << '"' << s->get() << '"';
    } else if (auto a = node.as_array()) {
      constexpr std::size_t kShown = 8;
      out << '[';
      for (std::size_t i = 0; i < a->size(); ++i) {
        if (i > 0) out << ", ";
        if (i == kShown) {
          out << "... (" << a->size() << " values)";
          break;
        }
        out << show(*a->get(i));
      }
      out << ']';
    } else if (node.is_table()) {
      out << "a table";
    } else {
      node.visit([&](const auto& v) { out << v; });
    }
    return out.str();
  }

  void reject_unknown_keys(const toml::table& table, const std::string& prefix) const {
    for (const auto& [k, node] : table) {
      const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
      const auto& known = known_keys();
      if (std::find(known.begin(), known.end(), key) == known.end())
        fail(&node, key, fmt::format("is not a known key (did you mean {}?)", nearest_known_key(key)));
      if (auto sub = node.as_table()) reject_unknown_keys(*sub, key);
    }
  }

  const toml::node* find(const std::string& key) const { return root_.at_path(key).node(); }

  const toml::table* table(const std::string& key, bool required) const {
    const toml::node* node = find(key);
    if (!node) {
      if (required) fail(nullptr, fmt::format("[{}]", key), "is required but missing");
      return nullptr;
    }
    if (!node->is_table()) fail(node, key, fmt::format("must be a table, got {}", show(*node)));
    return node->as_table();
  }

  std::optional<double> number(const std::string& key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    if (auto v = node->value<double>(); v && (node->is_floating_point() || node->is_integer())) {
      if (!std::isfinite(*v)) fail(node, key, fmt::format("must be a finite number, got {}", show(*node)));
      return *v;
    }
    fail(node, key, fmt::format("must be a number, got {}", show(*node)));
  }

  double number_or(const std::string& key, double fallback) const { return number(key).value_or(fallback); }

  double required_number(const std::string& key) const {
    if (auto v = number(key)) return *v;
    fail(nullptr, key, "is required but missing");
  }

  std::optional<Vec2> pair(const std::string& key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const toml::array* a = node->as_array();
    if (!a || a->size() != 2 || !(*a)[0].is_number() || !(*a)[1].is_number())
      fail(node, key, fmt::format("must be a pair of numbers [x, y], got {}", show(*node)));
    const Vec2 v{*(*a)[0].value<double>(), *(*a)[1].value<double>()};
    if (!std::isfinite(v.x) || !std::isfinite(v.y))
      fail(node, key, fmt::format("must be a pair of finite numbers, got [{}, {}]", v.x, v.y));
    return v;
  }

  std::optional<std::string> string(const std::string& key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    if (!node->is_string()) fail(node, key, fmt::format("must be a string, got {}", show(*node)));
    return node->as_string()->get();
  }

  std::optional<bool> boolean(const std::string& key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    if (!node->is_boolean()) fail(node, key, fmt::format("must be true or false, got {}", show(*node)));
    return node->as_boolean()->get();
  }

  void require(bool ok, const std::string& key, const std::string& rule, double value) const {
    if (!ok) fail(find(key), key, fmt::format("must be {}, got {}", rule, value));
  }
  void positive(const std::string& key, double value) const { require(value > 0.0, key, "> 0", value); }
  // A length > 0 within the sane range of lengths (kMinLengthMm .. kMaxLengthMm).
  void length(const std::string& key, double value, double min_mm = kMinLengthMm) const {
    positive(key, value);
    require(value >= min_mm && value <= kMaxLengthMm, key, fmt::format("between {} and {} mm", min_mm, kMaxLengthMm),
            value);
  }

 private:
  const toml::table& root_;
  std::string origin_;
};

// The figures `nelf design` reports and the compositor builds on, bounded (docs/profiles.md,
// "Limits"): the lens count by the panel's pixels, a field of view strictly between 0 and 180
// degrees, at least one resolvable pixel, no more views in the pupil than lenses, and every figure
// finite. Each is refused naming the key that sets it.
void check_derived_figures(const Reader& r, const Profile& p) {
  if (!p.lens_array && !p.magnifier) return;
  const bool lens_array = p.lens_array.has_value();
  const std::string table = lens_array ? "lens_array" : "magnifier";
  constexpr const char* axis_names[2] = {"horizontal", "vertical"};
  int lenses_across = 1;
  for (int axis = 0; axis < 2; ++axis) {
    const optics::AxisGeometry g = axis_geometry(p, axis);
    const char* axis_name = axis_names[axis];
    const int panel_px = p.display.resolution[static_cast<std::size_t>(axis)];
    if (lens_array) {
      const double elemental_px = optics::elemental_image_mm(g) / g.pixel_pitch_mm;
      if (!(elemental_px >= kMinElementalImagePx))
        r.fail(r.find("lens_array.pitch_mm"), "lens_array.pitch_mm",
               fmt::format("must give elemental images of at least {} px, got {:.3g} px {} ({:.4g} lenses across the "
                           "{} px panel, at most {})",
                           kMinElementalImagePx, elemental_px, axis_name, optics::lenses_fitting(g), panel_px,
                           static_cast<int>(panel_px / kMinElementalImagePx)));
      if (axis == 0) lenses_across = optics::lenses_used(g);
    }
    const double fov_deg = (lens_array ? optics::field_of_view_rad(g) : optics::magnifier::field_of_view_rad(g)) *
                           180.0 / std::numbers::pi;
    if (!(fov_deg > 0.0 && fov_deg < 180.0))
      r.fail(r.find("viewing.eye_relief_mm"), "viewing.eye_relief_mm",
             fmt::format("{} gives a {} field of view of {:.6g} deg, which must lie between 0 and 180 deg",
                         p.viewing.eye_relief_mm, axis_name, fov_deg));
    const int resolution = lens_array ? optics::resolution_px(g) : optics::magnifier::resolution_px(g);
    if (resolution < 1)
      r.fail(r.find(table + ".focal_length_mm"), table + ".focal_length_mm",
             fmt::format("{} magnifies so much that the {} resolution is {} px (Eq. 8); it must be at least 1 px",
                         g.focal_mm, axis_name, resolution));
    const double eye_box = lens_array ? optics::eye_box_mm(g) : optics::magnifier::eye_box_mm(g);
    const optics::DepthOfField dof = optics::depth_of_field(g);
    if (!std::isfinite(eye_box) || !std::isfinite(dof.near_mm) || (dof.far_mm && !std::isfinite(*dof.far_mm)))
      r.fail(r.find(table), "[" + table + "]",
             fmt::format("gives a {} eye box or depth of field that is not a finite number", axis_name));
  }
  if (lens_array) {
    // Eq. 15: a/w_l views enter the pupil; a pupil wider than the lit lens array would count lenses
    // that are not there.
    const double array_mm = lenses_across * p.lens_array->pitch_mm;
    r.require(p.viewing.pupil_mm <= array_mm, "viewing.pupil_mm",
              fmt::format("at most the lit lens array's width ({} lenses x {} mm = {:.4g} mm)", lenses_across,
                          p.lens_array->pitch_mm, array_mm),
              p.viewing.pupil_mm);
  }
  const double app_a =
      optics::simple_magnifier_min_focal_mm(p.magnifier_comparison.f_number, p.magnifier_comparison.eye_box_mm,
                                            p.viewing.eye_relief_mm, p.display.width_mm());
  if (!std::isfinite(app_a))
    r.fail(r.find("magnifier_comparison"), "[magnifier_comparison]", "gives a magnifier bound that is not finite");
}

// correction.defect_map, found beside the profile file (origin), read and validated against the
// panel. A missing file is the profile's error (its file, line and key); a bad line is the map's.
void read_profile_defect_map(const Reader& r, Profile& p, const std::string& origin) {
  const std::filesystem::path given(p.correction.defect_map);
  std::filesystem::path base;
  if (origin.rfind("built-in ", 0) != 0) base = std::filesystem::path(origin).parent_path();
  const std::filesystem::path path = given.is_absolute() || base.empty() ? given : base / given;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    r.fail(r.find("correction.defect_map"), "correction.defect_map",
           fmt::format("names \"{}\" ({}), which {}", p.correction.defect_map, path.string(),
                       std::filesystem::exists(path, ec) ? "is not a regular file" : "does not exist"));
  p.correction.defect_map_path = path;
  p.correction.defects = std::make_shared<const DefectMap>(read_defect_map(path, p.display.resolution));
}

Profile read_profile(const toml::table& root, const std::string& origin) {
  Reader r(root, origin);
  r.reject_unknown_keys(root, "");

  Profile p;
  p.source = origin;
  p.name = r.string("name").value_or("");
  p.description = r.string("description").value_or("");

  // [display]
  r.table("display", true);
  const toml::node* res = r.find("display.resolution");
  if (!res) r.fail(nullptr, "display.resolution", "is required but missing");
  const toml::array* res_array = res->as_array();
  if (!res_array || res_array->size() != 2 || !(*res_array)[0].is_integer() || !(*res_array)[1].is_integer())
    r.fail(res, "display.resolution",
           fmt::format("must be a pair of integers [width, height], got {}", Reader::show(*res)));
  for (int i = 0; i < 2; ++i) {
    const int64_t v = *(*res_array)[static_cast<std::size_t>(i)].value<int64_t>();
    if (v <= 0 || v > 16384)
      r.fail(res, "display.resolution", fmt::format("must be between 1 and 16384 pixels, got {}", Reader::show(*res)));
    p.display.resolution[static_cast<std::size_t>(i)] = static_cast<int>(v);
  }
  const auto pitch = r.number("display.pixel_pitch_mm");
  const auto size = r.pair("display.size_mm");
  if (pitch && size)
    r.fail(r.find("display.size_mm"), "display.size_mm", "conflicts with display.pixel_pitch_mm: give one of them");
  if (pitch) {
    r.positive("display.pixel_pitch_mm", *pitch);
    p.display.pixel_pitch_mm = {*pitch, *pitch};
  } else if (size) {
    if (!(size->x > 0.0 && size->y > 0.0))
      r.fail(r.find("display.size_mm"), "display.size_mm", fmt::format("must be > 0, got [{}, {}]", size->x, size->y));
    p.display.pixel_pitch_mm = {size->x / p.display.resolution[0], size->y / p.display.resolution[1]};
  } else {
    r.fail(nullptr, "display.pixel_pitch_mm", "is required but missing (or give display.size_mm)");
  }
  {
    const std::string key = pitch ? "display.pixel_pitch_mm" : "display.size_mm";
    const double finest = std::min(p.display.pixel_pitch_mm.x, p.display.pixel_pitch_mm.y);
    if (finest < kMinPixelPitchMm)
      r.fail(r.find(key), key,
             fmt::format("must give a pixel pitch of at least {} mm, got {:.6g} mm", kMinPixelPitchMm, finest));
    const double w = p.display.width_mm(), h = p.display.height_mm();
    if (w > kMaxPanelMm || h > kMaxPanelMm)
      r.fail(r.find(key), key,
             fmt::format("must give a panel of at most {} mm a side, got {:.6g} x {:.6g} mm ({} x {} px)", kMaxPanelMm,
                         w, h, p.display.resolution[0], p.display.resolution[1]));
  }

  // [viewing]
  r.table("viewing", true);
  p.viewing.eye_relief_mm = r.required_number("viewing.eye_relief_mm");
  p.viewing.virtual_image_mm = r.required_number("viewing.virtual_image_mm");
  p.viewing.pupil_mm = r.number_or("viewing.pupil_mm", p.viewing.pupil_mm);
  p.viewing.ipd_mm = r.number_or("viewing.ipd_mm", p.viewing.ipd_mm);
  r.length("viewing.eye_relief_mm", p.viewing.eye_relief_mm);
  r.length("viewing.virtual_image_mm", p.viewing.virtual_image_mm);
  r.length("viewing.pupil_mm", p.viewing.pupil_mm);
  r.length("viewing.ipd_mm", p.viewing.ipd_mm);

  // [lens_array]
  if (r.table("lens_array", false)) {
    LensArraySpec lens;
    lens.pitch_mm = r.required_number("lens_array.pitch_mm");
    lens.focal_length_mm = r.required_number("lens_array.focal_length_mm");
    lens.gap_mm = r.number("lens_array.gap_mm");
    lens.rotation_deg = r.number_or("lens_array.rotation_deg", 0.0);
    lens.offset_mm = r.pair("lens_array.offset_mm").value_or(Vec2{});
    r.length("lens_array.pitch_mm", lens.pitch_mm);
    r.length("lens_array.focal_length_mm", lens.focal_length_mm);
    r.require(std::abs(lens.rotation_deg) <= 180.0, "lens_array.rotation_deg", "between -180 and 180",
              lens.rotation_deg);
    // The lattice's centre stays on the panel, or the lit block of lenses slides off it.
    const Vec2 half_panel{p.display.width_mm() / 2.0, p.display.height_mm() / 2.0};
    if (!(std::abs(lens.offset_mm.x) <= half_panel.x && std::abs(lens.offset_mm.y) <= half_panel.y))
      r.fail(r.find("lens_array.offset_mm"), "lens_array.offset_mm",
             fmt::format("must be within half the panel ([-{:.6g}, {:.6g}] x [-{:.6g}, {:.6g}] mm), got [{}, {}]",
                         half_panel.x, half_panel.x, half_panel.y, half_panel.y, lens.offset_mm.x, lens.offset_mm.y));
    if (lens.gap_mm) {
      r.length("lens_array.gap_mm", *lens.gap_mm);
      r.require(*lens.gap_mm < lens.focal_length_mm, "lens_array.gap_mm",
                fmt::format("< lens_array.focal_length_mm ({}) for a virtual image", lens.focal_length_mm),
                *lens.gap_mm);
    }
    const double display_min = std::min(p.display.width_mm(), p.display.height_mm());
    r.require(lens.pitch_mm <= display_min, "lens_array.pitch_mm",
              fmt::format("<= the display's smaller side ({:.4g} mm)", display_min), lens.pitch_mm);
    const double min_image = p.viewing.eye_relief_mm + lens.focal_length_mm;
    r.require(p.viewing.virtual_image_mm > min_image, "viewing.virtual_image_mm",
              fmt::format("> viewing.eye_relief_mm + lens_array.focal_length_mm ({})", min_image),
              p.viewing.virtual_image_mm);
    p.lens_array = lens;
  }

  // [magnifier]
  if (r.table("magnifier", false)) {
    if (p.lens_array)
      r.fail(r.find("magnifier"), "magnifier",
             "describes a stock device's single lens and cannot be combined with [lens_array]");
    MagnifierSpec mag;
    mag.width_mm = r.required_number("magnifier.width_mm");
    mag.focal_length_mm = r.required_number("magnifier.focal_length_mm");
    r.length("magnifier.width_mm", mag.width_mm);
    r.length("magnifier.focal_length_mm", mag.focal_length_mm);
    const double min_image = p.viewing.eye_relief_mm + mag.focal_length_mm;
    r.require(p.viewing.virtual_image_mm > min_image, "viewing.virtual_image_mm",
              fmt::format("> viewing.eye_relief_mm + magnifier.focal_length_mm ({})", min_image),
              p.viewing.virtual_image_mm);
    p.magnifier = mag;
  }

  // [screen]
  r.table("screen", false);
  p.screen.distance_mm = r.number_or("screen.distance_mm", 0.0);
  p.screen.width_mm = r.number_or("screen.width_mm", 0.0);
  p.screen.converge = r.boolean("screen.converge").value_or(true);
  r.require(p.screen.width_mm >= 0.0, "screen.width_mm", ">= 0 (0 = largest that fits)", p.screen.width_mm);
  r.require(p.screen.width_mm <= kMaxLengthMm, "screen.width_mm", fmt::format("at most {} mm", kMaxLengthMm),
            p.screen.width_mm);
  r.require(p.screen.distance_mm <= kMaxLengthMm, "screen.distance_mm", fmt::format("at most {} mm", kMaxLengthMm),
            p.screen.distance_mm);
  if (p.screen.distance_mm != 0.0) {
    double nearest = p.viewing.eye_relief_mm;
    if (p.lens_array)
      nearest += p.lens_array->gap_mm.value_or(
          optics::gap_mm(p.lens_array->focal_length_mm, p.viewing.virtual_image_mm, p.viewing.eye_relief_mm));
    r.require(p.screen.distance_mm > nearest, "screen.distance_mm",
              fmt::format("0 (= virtual_image_mm) or beyond the display ({:.4g} mm)", nearest), p.screen.distance_mm);
  }

  // [output]
  r.table("output", false);
  p.signal = r.string("output.signal").value_or(p.signal);
  const auto& signals = known_signals();
  if (std::find(signals.begin(), signals.end(), p.signal) == signals.end())
    r.fail(r.find("output.signal"), "output.signal",
           fmt::format("must be one of {}, got \"{}\"", fmt::join(signals, ", "), p.signal));

  // [calibration.left] / [calibration.right]
  r.table("calibration", false);
  for (Eye eye : {Eye::left, Eye::right}) {
    const std::string t = eye == Eye::left ? "calibration.left" : "calibration.right";
    r.table(t, false);
    EyeCalibration& c = p.calibration[static_cast<std::size_t>(eye)];
    c.shift_px = r.pair(t + ".shift_px").value_or(Vec2{});
    c.rotation_deg = r.number_or(t + ".rotation_deg", 0.0);
    c.pitch_scale = r.number_or(t + ".pitch_scale", 1.0);
    r.positive(t + ".pitch_scale", c.pitch_scale);
    r.require(c.pitch_scale >= kMinPitchScale && c.pitch_scale <= kMaxPitchScale, t + ".pitch_scale",
              fmt::format("between {} and {}", kMinPitchScale, kMaxPitchScale), c.pitch_scale);
    // Half the panel either way (as the calibrate keys allow): beyond it the image is off the panel.
    const double half_w = p.display.resolution[0] / 2.0, half_h = p.display.resolution[1] / 2.0;
    if (!(std::abs(c.shift_px.x) <= half_w && std::abs(c.shift_px.y) <= half_h))
      r.fail(r.find(t + ".shift_px"), t + ".shift_px",
             fmt::format("must be within half the panel ([-{}, {}] x [-{}, {}] px), got [{}, {}]", half_w, half_w,
                         half_h, half_h, c.shift_px.x, c.shift_px.y));
    r.require(std::abs(c.rotation_deg) <= 180.0, t + ".rotation_deg", "between -180 and 180", c.rotation_deg);
  }

  // [correction]
  r.table("correction", false);
  p.correction.prescription_diopters = r.number_or("correction.prescription_diopters", 0.0);
  p.correction.defect_map = r.string("correction.defect_map").value_or("");
  r.require(std::abs(p.correction.prescription_diopters) <= 20.0, "correction.prescription_diopters",
            "between -20 and 20", p.correction.prescription_diopters);
  if (p.lens_array && p.correction.prescription_diopters < 0.0) {
    // A myope's far point pulls the emulated screen in (render_distance_mm); it must stay beyond
    // the display like screen.distance_mm.
    const double far_point = 1000.0 / -p.correction.prescription_diopters;
    const double nearest = p.viewing.eye_relief_mm +
                           p.lens_array->gap_mm.value_or(optics::gap_mm(
                               p.lens_array->focal_length_mm, p.viewing.virtual_image_mm, p.viewing.eye_relief_mm));
    if (far_point <= nearest)
      r.fail(r.find("correction.prescription_diopters"), "correction.prescription_diopters",
             fmt::format("puts the far point at {:.4g} mm, which must lie beyond the display ({:.4g} mm), got {}",
                         far_point, nearest, p.correction.prescription_diopters));
  }

  // [magnifier_comparison]
  r.table("magnifier_comparison", false);
  p.magnifier_comparison.eye_box_mm = r.number_or("magnifier_comparison.eye_box_mm", 10.0);
  p.magnifier_comparison.f_number = r.number_or("magnifier_comparison.f_number", 1.0);
  r.length("magnifier_comparison.eye_box_mm", p.magnifier_comparison.eye_box_mm);
  r.positive("magnifier_comparison.f_number", p.magnifier_comparison.f_number);
  r.require(p.magnifier_comparison.f_number <= kMaxFNumber, "magnifier_comparison.f_number",
            fmt::format("at most {}", kMaxFNumber), p.magnifier_comparison.f_number);

  check_derived_figures(r, p);
  if (!p.correction.defect_map.empty()) read_profile_defect_map(r, p, origin);
  return p;
}

std::string builtin_file_name(const std::string& name) { return name + ".toml"; }

}  // namespace

Profile parse_profile(std::string_view toml_text, const std::string& origin) {
  toml::table root;
  try {
    root = toml::parse(toml_text, origin);
  } catch (const toml::parse_error& e) {
    throw ProfileError(fmt::format("{}:{}: TOML syntax error: {}", origin, e.source().begin.line, e.description()));
  }
  return read_profile(root, origin);
}

std::vector<BuiltinProfileInfo> builtin_profiles() {
  std::vector<BuiltinProfileInfo> list;
  for (const auto& file : embedded::nelf_embedded_profiles()) {
    std::string name(file.name.substr(0, file.name.size() - 5));  // strip ".toml"
    const Profile p = parse_profile(file.contents, "built-in " + name);
    list.push_back({p.name.empty() ? name : p.name, p.description});
  }
  std::sort(list.begin(), list.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  return list;
}

Profile load_profile(const std::string& name_or_path) {
  if (auto builtin = embedded::find(embedded::nelf_embedded_profiles(), builtin_file_name(name_or_path))) {
    Profile p = parse_profile(*builtin, "built-in " + name_or_path);
    if (p.name.empty()) p.name = name_or_path;
    return p;
  }
  const bool looks_like_path =
      name_or_path.find('/') != std::string::npos || name_or_path.find('.') != std::string::npos;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(name_or_path, ec)) {
    std::vector<std::string> names;
    for (const auto& b : builtin_profiles()) names.push_back(b.name);
    if (looks_like_path || std::filesystem::exists(name_or_path, ec))
      throw ProfileError(fmt::format("{}: cannot read profile: no such file (built-in profiles: {})", name_or_path,
                                     fmt::join(names, ", ")));
    throw ProfileError(fmt::format("unknown profile '{}': not a file and not a built-in (built-in profiles: {})",
                                   name_or_path, fmt::join(names, ", ")));
  }
  std::ifstream in(name_or_path, std::ios::binary);
  if (!in) throw ProfileError(fmt::format("{}: cannot read profile: permission denied or unreadable", name_or_path));
  std::ostringstream text;
  text << in.rdbuf();
  Profile p = parse_profile(text.str(), name_or_path);
  if (p.name.empty()) p.name = std::filesystem::path(name_or_path).stem().string();
  return p;
}

namespace {
// A TOML basic string with quotes, backslashes and control characters escaped (toml++'s formatter),
// so that any name, description or path read from a profile is written back loadable.
std::string toml_string(const std::string& text) {
  std::ostringstream quoted;
  quoted << toml::value<std::string>(text);
  return quoted.str();
}
}  // namespace

std::string profile_to_toml(const Profile& p) {
  const auto pair = [](Vec2 v) { return fmt::format("[{}, {}]", v.x, v.y); };
  std::string out;
  out += fmt::format("name = {}\n", toml_string(p.name));
  if (!p.description.empty()) out += fmt::format("description = {}\n", toml_string(p.description));
  out += fmt::format("\n[display]\nresolution = [{}, {}]\n", p.display.resolution[0], p.display.resolution[1]);
  if (p.display.pixel_pitch_mm.x == p.display.pixel_pitch_mm.y)
    out += fmt::format("pixel_pitch_mm = {}\n", p.display.pixel_pitch_mm.x);
  else
    out += fmt::format("size_mm = [{}, {}]\n", p.display.width_mm(), p.display.height_mm());
  if (p.lens_array) {
    const auto& l = *p.lens_array;
    out += fmt::format("\n[lens_array]\npitch_mm = {}\nfocal_length_mm = {}\n", l.pitch_mm, l.focal_length_mm);
    if (l.gap_mm) out += fmt::format("gap_mm = {}\n", *l.gap_mm);
    out += fmt::format("rotation_deg = {}\noffset_mm = {}\n", l.rotation_deg, pair(l.offset_mm));
  }
  if (p.magnifier)
    out += fmt::format("\n[magnifier]\nwidth_mm = {}\nfocal_length_mm = {}\n", p.magnifier->width_mm,
                       p.magnifier->focal_length_mm);
  out += fmt::format("\n[viewing]\neye_relief_mm = {}\nvirtual_image_mm = {}\npupil_mm = {}\nipd_mm = {}\n",
                     p.viewing.eye_relief_mm, p.viewing.virtual_image_mm, p.viewing.pupil_mm, p.viewing.ipd_mm);
  out += fmt::format("\n[screen]\ndistance_mm = {}\nwidth_mm = {}\nconverge = {}\n", p.screen.distance_mm,
                     p.screen.width_mm, p.screen.converge);
  out += fmt::format("\n[output]\nsignal = {}\n", toml_string(p.signal));
  for (Eye eye : {Eye::left, Eye::right}) {
    const auto& c = p.eye_calibration(eye);
    out += fmt::format("\n[calibration.{}]\nshift_px = {}\nrotation_deg = {}\npitch_scale = {}\n",
                       eye == Eye::left ? "left" : "right", pair(c.shift_px), c.rotation_deg, c.pitch_scale);
  }
  out += fmt::format("\n[correction]\nprescription_diopters = {}\ndefect_map = {}\n",
                     p.correction.prescription_diopters, toml_string(p.correction.defect_map));
  out += fmt::format("\n[magnifier_comparison]\neye_box_mm = {}\nf_number = {}\n", p.magnifier_comparison.eye_box_mm,
                     p.magnifier_comparison.f_number);
  return out;
}

optics::AxisGeometry axis_geometry(const Profile& profile, int axis) {
  optics::AxisGeometry g;
  g.display_mm = axis == 0 ? profile.display.width_mm() : profile.display.height_mm();
  g.pixel_pitch_mm = axis == 0 ? profile.display.pixel_pitch_mm.x : profile.display.pixel_pitch_mm.y;
  g.eye_relief_mm = profile.viewing.eye_relief_mm;
  g.image_mm = profile.viewing.virtual_image_mm;
  if (profile.lens_array) {
    g.lens_pitch_mm = profile.lens_array->pitch_mm;
    g.focal_mm = profile.lens_array->focal_length_mm;
    g.gap_mm = profile.lens_array->gap_mm;
  } else if (profile.magnifier) {
    g.lens_pitch_mm = profile.magnifier->width_mm;
    g.focal_mm = profile.magnifier->focal_length_mm;
  } else {
    throw std::logic_error("axis_geometry: profile '" + profile.name + "' has neither a lens array nor a magnifier");
  }
  return g;
}

}  // namespace nelf
