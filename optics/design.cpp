#include "optics/design.hpp"

#include <fmt/format.h>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <vector>

#include "optics/mapping.hpp"

namespace nelf {

namespace {

double degrees(double radians) { return radians * 180.0 / std::acos(-1.0); }

// Width of a UTF-8 string in terminal columns, counting one column per code point: the table uses
// Greek symbols and "×", which are one column wide but several bytes long.
std::size_t columns(const std::string& s) {
  std::size_t n = 0;
  for (unsigned char c : s)
    if ((c & 0xC0) != 0x80) ++n;
  return n;
}

std::string pad_right(const std::string& s, std::size_t width) {
  const std::size_t w = columns(s);
  return w >= width ? s : s + std::string(width - w, ' ');
}

std::string pad_left(const std::string& s, std::size_t width) {
  const std::size_t w = columns(s);
  return w >= width ? s : std::string(width - w, ' ') + s;
}

}  // namespace

DesignReport design_report(const Profile& profile) {
  DesignReport r;
  r.profile = profile.name;
  r.description = profile.description;
  r.source = profile.source;
  r.panel_px = profile.display.resolution;
  r.pixel_pitch_mm = profile.display.pixel_pitch_mm;
  r.display_mm = {profile.display.width_mm(), profile.display.height_mm()};
  r.eye_relief_mm = profile.viewing.eye_relief_mm;
  r.virtual_image_mm = profile.viewing.virtual_image_mm;
  r.pupil_mm = profile.viewing.pupil_mm;
  r.comparison_f_number = profile.magnifier_comparison.f_number;
  r.comparison_eye_box_mm = profile.magnifier_comparison.eye_box_mm;
  r.simple_magnifier_min_focal_mm = optics::simple_magnifier_min_focal_mm(
      r.comparison_f_number, r.comparison_eye_box_mm, r.eye_relief_mm, r.display_mm.x);

  r.kind = profile.lens_array  ? DesignOptics::lens_array
           : profile.magnifier ? DesignOptics::magnifier
                               : DesignOptics::none;
  if (r.kind == DesignOptics::none) return r;

  const bool single_lens = r.kind == DesignOptics::magnifier;
  OpticalDesign o;
  for (int axis = 0; axis < 2; ++axis) {
    const optics::AxisGeometry g = axis_geometry(profile, axis);
    AxisDesign& a = o.axis[static_cast<std::size_t>(axis)];
    if (single_lens) {
      a.elemental_image_mm = g.display_mm;
      a.lenses = 1;
      a.fov_deg = degrees(optics::magnifier::field_of_view_rad(g));
      a.resolution_px = optics::magnifier::resolution_px(g);
      a.eye_box_mm = optics::magnifier::eye_box_mm(g);
    } else {
      a.elemental_image_mm = optics::elemental_image_mm(g);
      a.lenses = optics::lenses_used(g);
      a.fov_deg = degrees(optics::field_of_view_rad(g));
      a.resolution_px = optics::resolution_px(g);
      a.eye_box_mm = optics::eye_box_mm(g);
    }
    a.depth_of_field = optics::depth_of_field(g);
    if (axis == 0) {
      o.lens_width_mm = g.lens_pitch_mm;
      o.focal_mm = g.focal_mm;
      o.gap_mm = profile.lens_array ? lens_gap_mm(profile) : optics::gap_mm(g.focal_mm, g.image_mm, g.eye_relief_mm);
      // With a fixed gap the thin-lens magnification f/(f − d_l) is the one the hardware has; it
      // equals Eq. 2 when the gap comes from Eq. 1.
      o.magnification = g.gap_mm ? g.focal_mm / (g.focal_mm - *g.gap_mm)
                                 : optics::magnification(g.focal_mm, g.image_mm, g.eye_relief_mm);
    }
  }
  // Eq. 15 counts the lenses whose views enter the pupil. A single magnifier is one view however
  // large it is (the formula would floor to 0 for a lens wider than the pupil).
  o.views = single_lens ? 1
                        : optics::views_in_pupil(std::numeric_limits<double>::infinity(), r.eye_relief_mm, r.pupil_mm,
                                                 o.lens_width_mm);
  for (std::size_t i = 0; i < kDiffractionWavelengthsNm.size(); ++i)
    o.diffraction_pitch_um[i] = optics::diffraction_pitch_um(kDiffractionWavelengthsNm[i], o.gap_mm, o.lens_width_mm);
  r.optics = o;
  return r;
}

nlohmann::json design_to_json(const DesignReport& r) {
  using nlohmann::json;
  json j = json::object();
  j["profile"] = r.profile;
  j["optics"] = r.kind == DesignOptics::lens_array  ? "lens_array"
                : r.kind == DesignOptics::magnifier ? "magnifier"
                                                    : "none";
  j["display"] = {
      {"resolution_px", {r.panel_px[0], r.panel_px[1]}},
      {"pixel_pitch_mm", {r.pixel_pitch_mm.x, r.pixel_pitch_mm.y}},
      {"size_mm", {r.display_mm.x, r.display_mm.y}},
  };
  j["viewing"] = {
      {"eye_relief_mm", r.eye_relief_mm},
      {"virtual_image_mm", r.virtual_image_mm},
      {"pupil_mm", r.pupil_mm},
  };
  const json null_pair = json::array({nullptr, nullptr});
  if (r.optics) {
    const OpticalDesign& o = *r.optics;
    const AxisDesign& h = o.axis[0];
    const AxisDesign& v = o.axis[1];
    j["gap_mm"] = o.gap_mm;
    j["magnification"] = o.magnification;
    j["elemental_image_mm"] = h.elemental_image_mm;
    j["lenses"] = {h.lenses, v.lenses};
    j["fov_deg"] = {h.fov_deg, v.fov_deg};
    j["resolution_px"] = {h.resolution_px, v.resolution_px};
    j["eye_box_mm"] = h.eye_box_mm;
    j["depth_of_field_mm"] = {h.depth_of_field.near_mm,
                              h.depth_of_field.far_mm ? json(*h.depth_of_field.far_mm) : json(nullptr)};
    j["views"] = o.views;
    json diffraction = json::object();
    for (std::size_t i = 0; i < kDiffractionWavelengthsNm.size(); ++i)
      diffraction[std::to_string(kDiffractionWavelengthsNm[i])] = o.diffraction_pitch_um[i];
    j["diffraction_pitch_um"] = diffraction;
  } else {
    for (const char* key : {"gap_mm", "magnification", "elemental_image_mm", "eye_box_mm", "views"}) j[key] = nullptr;
    for (const char* key : {"lenses", "fov_deg", "resolution_px", "depth_of_field_mm"}) j[key] = null_pair;
    json diffraction = json::object();
    for (int nm : kDiffractionWavelengthsNm) diffraction[std::to_string(nm)] = nullptr;
    j["diffraction_pitch_um"] = diffraction;
  }
  j["simple_magnifier_min_focal_mm"] = r.simple_magnifier_min_focal_mm;
  return j;
}

std::string design_table(const DesignReport& r) {
  std::string out;
  out += fmt::format("profile   {} ({})\n", r.profile, r.source);
  if (!r.description.empty()) out += fmt::format("          {}\n", r.description);
  out += fmt::format("panel     {} × {} px, pixel pitch {:.4g} × {:.4g} µm, {:.4g} × {:.4g} mm\n", r.panel_px[0],
                     r.panel_px[1], r.pixel_pitch_mm.x * 1e3, r.pixel_pitch_mm.y * 1e3, r.display_mm.x, r.display_mm.y);
  switch (r.kind) {
    case DesignOptics::lens_array:
      out += fmt::format("optics    lens array: pitch w_l {:.4g} mm, focal length f {:.4g} mm (f/{:.3g})\n",
                         r.optics->lens_width_mm, r.optics->focal_mm, r.optics->focal_mm / r.optics->lens_width_mm);
      break;
    case DesignOptics::magnifier:
      out += fmt::format("optics    single magnifier: width w_l {:.4g} mm, focal length f {:.4g} mm (f/{:.3g})\n",
                         r.optics->lens_width_mm, r.optics->focal_mm, r.optics->focal_mm / r.optics->lens_width_mm);
      break;
    case DesignOptics::none:
      out += "optics    none described: no [lens_array] or [magnifier], optical figures are not reported\n";
      break;
  }
  out += fmt::format("viewing   eye relief d_e {:.4g} mm, virtual image d_o {:.6g} mm, pupil a {:.4g} mm\n\n",
                     r.eye_relief_mm, r.virtual_image_mm, r.pupil_mm);

  struct Row {
    std::string quantity, horizontal, vertical, unit;
  };
  std::vector<Row> rows;
  const std::string none = "—";
  const auto both = [&](const std::string& q, const std::string& unit, auto&& value_of) {
    if (!r.optics) return rows.push_back({q, none, none, unit});
    rows.push_back({q, value_of(r.optics->axis[0]), value_of(r.optics->axis[1]), unit});
  };
  const auto scalar = [&](const std::string& q, const std::string& unit, auto&& value_of) {
    rows.push_back({q, r.optics ? value_of(*r.optics) : none, "", unit});
  };
  scalar("gap d_l (Eq. 1)", "mm", [](const OpticalDesign& o) { return fmt::format("{:.3f}", o.gap_mm); });
  scalar("magnification M (Eq. 2)", "", [](const OpticalDesign& o) { return fmt::format("{:.1f}", o.magnification); });
  both("elemental image Δw_s (Eq. 6)", "mm",
       [](const AxisDesign& a) { return fmt::format("{:.4f}", a.elemental_image_mm); });
  both("lenses used N_l (Eq. 6)", "", [](const AxisDesign& a) { return fmt::format("{}", a.lenses); });
  both("field of view α (Eq. 7)", "°", [](const AxisDesign& a) { return fmt::format("{:.1f}", a.fov_deg); });
  both("resolution N_p (Eq. 8)", "px", [](const AxisDesign& a) { return fmt::format("{}", a.resolution_px); });
  both("eye box w_e (Eq. 9)", "mm", [](const AxisDesign& a) { return fmt::format("{:.2f}", a.eye_box_mm); });
  both("depth of field, near", "mm",
       [](const AxisDesign& a) { return fmt::format("{:.1f}", a.depth_of_field.near_mm); });
  both("depth of field, far", "mm", [](const AxisDesign& a) {
    return a.depth_of_field.far_mm ? fmt::format("{:.1f}", *a.depth_of_field.far_mm) : std::string("∞");
  });
  scalar("views in pupil N_v (Eq. 15)", "", [](const OpticalDesign& o) { return fmt::format("{}", o.views); });
  for (std::size_t i = 0; i < kDiffractionWavelengthsNm.size(); ++i)
    scalar(fmt::format("diffraction pitch limit {} nm", kDiffractionWavelengthsNm[i]), "µm",
           [i](const OpticalDesign& o) { return fmt::format("{:.2f}", o.diffraction_pitch_um[i]); });
  rows.push_back({"simple magnifier min f (App. A)", fmt::format("{:.2f}", r.simple_magnifier_min_focal_mm), "", "mm"});

  std::size_t quantity_width = columns("quantity"), value_width = columns("horizontal");
  for (const Row& row : rows) {
    quantity_width = std::max(quantity_width, columns(row.quantity));
    value_width = std::max({value_width, columns(row.horizontal), columns(row.vertical)});
  }
  const auto line = [&](const Row& row) {
    std::string s = pad_right(row.quantity, quantity_width) + "  " + pad_left(row.horizontal, value_width) + "  " +
                    pad_left(row.vertical, value_width) + "  " + row.unit;
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s + "\n";
  };
  out += line({"quantity", "horizontal", "vertical", "unit"});
  for (const Row& row : rows) out += line(row);
  out += fmt::format(
      "\nApp. A: a single f/{:.3g} magnifier with a {:.3g} mm eye box needs f >= {:.2f} mm for this display\n"
      "([magnifier_comparison] in the profile sets the f-number and the eye box).\n",
      r.comparison_f_number, r.comparison_eye_box_mm, r.simple_magnifier_min_focal_mm);
  if (!r.optics)
    out +=
        "No [lens_array] or [magnifier] in this profile: its optics are outside the model, so the optical\n"
        "figures are not reported. Describe the lens with a [magnifier] table (width_mm, focal_length_mm).\n";
  return out;
}

}  // namespace nelf
