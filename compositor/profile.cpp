#include "compositor/profile.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>
#include <algorithm>
#include <fstream>
#include <sstream>

#include "compositor/embedded.hpp"
#include "compositor/optics.hpp"

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
  static const std::vector<std::string> signals = {"hdmi-fp-720p60", "hdmi-fp-720p50", "hdmi-fp-1080p24"};
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
    return Vec2{*(*a)[0].value<double>(), *(*a)[1].value<double>()};
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

 private:
  const toml::table& root_;
  std::string origin_;
};

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

  // [viewing]
  r.table("viewing", true);
  p.viewing.eye_relief_mm = r.required_number("viewing.eye_relief_mm");
  p.viewing.virtual_image_mm = r.required_number("viewing.virtual_image_mm");
  p.viewing.pupil_mm = r.number_or("viewing.pupil_mm", p.viewing.pupil_mm);
  p.viewing.ipd_mm = r.number_or("viewing.ipd_mm", p.viewing.ipd_mm);
  r.positive("viewing.eye_relief_mm", p.viewing.eye_relief_mm);
  r.positive("viewing.virtual_image_mm", p.viewing.virtual_image_mm);
  r.positive("viewing.pupil_mm", p.viewing.pupil_mm);
  r.positive("viewing.ipd_mm", p.viewing.ipd_mm);

  // [lens_array]
  if (r.table("lens_array", false)) {
    LensArraySpec lens;
    lens.pitch_mm = r.required_number("lens_array.pitch_mm");
    lens.focal_length_mm = r.required_number("lens_array.focal_length_mm");
    lens.gap_mm = r.number("lens_array.gap_mm");
    lens.rotation_deg = r.number_or("lens_array.rotation_deg", 0.0);
    lens.offset_mm = r.pair("lens_array.offset_mm").value_or(Vec2{});
    r.positive("lens_array.pitch_mm", lens.pitch_mm);
    r.positive("lens_array.focal_length_mm", lens.focal_length_mm);
    if (lens.gap_mm) {
      r.positive("lens_array.gap_mm", *lens.gap_mm);
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
    r.positive("magnifier.width_mm", mag.width_mm);
    r.positive("magnifier.focal_length_mm", mag.focal_length_mm);
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
    r.require(std::abs(c.rotation_deg) <= 180.0, t + ".rotation_deg", "between -180 and 180", c.rotation_deg);
  }

  // [correction]
  r.table("correction", false);
  p.correction.prescription_diopters = r.number_or("correction.prescription_diopters", 0.0);
  p.correction.defect_map = r.string("correction.defect_map").value_or("");
  r.require(std::abs(p.correction.prescription_diopters) <= 20.0, "correction.prescription_diopters",
            "between -20 and 20", p.correction.prescription_diopters);

  // [magnifier_comparison]
  r.table("magnifier_comparison", false);
  p.magnifier_comparison.eye_box_mm = r.number_or("magnifier_comparison.eye_box_mm", 10.0);
  p.magnifier_comparison.f_number = r.number_or("magnifier_comparison.f_number", 1.0);
  r.positive("magnifier_comparison.eye_box_mm", p.magnifier_comparison.eye_box_mm);
  r.positive("magnifier_comparison.f_number", p.magnifier_comparison.f_number);
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

}  // namespace nelf
