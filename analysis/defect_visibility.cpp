#include "analysis/defect_visibility.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace nelf {

namespace {

constexpr double degrees_per_radian = 180.0 / std::numbers::pi;

double luminance(const Rgba& p) { return (static_cast<double>(p.r) + p.g + p.b) / 3.0; }

void check_panel_size(const Image& image, std::array<int, 2> panel, const char* what) {
  if (image.width() != panel[0] || image.height() != panel[1])
    throw std::invalid_argument(
        fmt::format("{} is {}x{}, the panel is {}x{}", what, image.width(), image.height(), panel[0], panel[1]));
}

struct Spot {
  std::size_t defect = 0;
  int i = 0, j = 0;  // retinal pixel of the defect's screen point
};

}  // namespace

Image defective_display(const DefectMap& map, Eye eye, Image sent) {
  show_defects(map, eye, sent);
  return sent;
}

Image compensated_display(const EyeDefectPlan& plan, const Image& sent) {
  check_panel_size(sent, plan.panel, "compensated_display: the eye image");
  Image out = sent;
  compensate_defects(plan, out);
  return out;
}

std::vector<DefectVisibility> measure_defect_visibility(const EyeSimulator& simulator, const EyeMapping& rendering,
                                                        const std::vector<PixelDefect>& defects, const Image& clean,
                                                        const std::vector<const Image*>& displays, double pupil_mm,
                                                        const DefectMeasurementOptions& options) {
  if (!rendering.has_lens_array) throw std::invalid_argument("defect measurement: the rendering has no lens array");
  if (options.eye_box_grid < 1 || options.accommodation_offsets_diopters.empty() ||
      !(options.window_footprints > 0.0) || !(options.contrast_floor > 0.0))
    throw std::invalid_argument("defect measurement: needs a pupil grid, an accommodation, a window and a floor");
  check_panel_size(clean, rendering.panel, "defect measurement: the clean display");
  for (const Image* display : displays) check_panel_size(*display, rendering.panel, "defect measurement: a display");

  const VisualField& field = simulator.field();
  const double d_r = rendering.render_distance_mm;
  const double k = (d_r - rendering.eye_relief_mm) / rendering.gap_mm;
  // One display footprint on the retina, in retinal pixels (visual_field_for_screen's step).
  const double footprint_deg =
      std::atan(std::min(rendering.pixel_pitch_mm.x, rendering.pixel_pitch_mm.y) * k / d_r) * degrees_per_radian;
  const int radius = static_cast<int>(std::ceil(options.window_footprints * footprint_deg / field.step_deg));

  // The defects' screen points; defects outside the lit elemental images show nothing anyone sees.
  std::vector<Vec2> screen_points(defects.size());
  std::vector<bool> lit(defects.size(), false);
  // (Stuck pixels beside the lit block too, whose lens shows them on the screen: defect_screen_point.)
  for (std::size_t n = 0; n < defects.size(); ++n) {
    const auto v = defect_screen_point(rendering, defects[n]);
    if (!v) continue;
    lit[n] = true;
    screen_points[n] = *v;
  }

  struct Accumulator {
    double worst = 0, sum = 0;
    std::size_t samples = 0;
    void add(double c) { worst = std::max(worst, c), sum += c, ++samples; }
  };
  struct PerDisplay {
    Accumulator all, dead, stuck;
    double squared_error = 0;
  };
  std::vector<PerDisplay> totals(displays.size());
  std::vector<bool> measured(defects.size(), false);
  std::size_t evaluated_total = 0;

  const auto clear = simulator.clear_field_mask(pupil_mm);
  const std::size_t field_pixels = static_cast<std::size_t>(field.width) * static_cast<std::size_t>(field.height);
  std::vector<int> slot(field_pixels, -1);  // retinal pixel → its index in the traced list, −1 untraced
  for (const Vec2& position : eye_box_pupil_positions(rendering, pupil_mm, options.eye_box_grid)) {
    for (double diopters : options.accommodation_offsets_diopters) {
      EyeModel eye;
      eye.pupil_mm = pupil_mm;
      eye.offset_mm = position;
      eye.pupil_samples_per_axis = options.pupil_samples_per_axis;
      const double vergence = 1000.0 / d_r + diopters;
      eye.focus_mm = vergence > 0.0 ? 1000.0 / vergence : std::numeric_limits<double>::infinity();

      std::vector<std::uint8_t> evaluated = simulator.on_screen_mask(eye);
      for (std::size_t p = 0; p < field_pixels; ++p) {
        evaluated[p] &= clear[p];
        evaluated_total += evaluated[p];
      }
      // Where each defect's screen point lands for this pupil (the chief ray from the pupil's centre),
      // and the union of the windows around those spots.
      std::vector<Spot> spots;
      std::vector<std::array<int, 2>> traced;
      for (std::size_t n = 0; n < defects.size(); ++n) {
        if (!lit[n]) continue;
        const Vec2 v = screen_points[n];
        const double x_deg = std::atan((v.x - position.x) / d_r) * degrees_per_radian;
        const double y_deg = std::atan((v.y - position.y) / d_r) * degrees_per_radian;
        const int i = static_cast<int>(std::floor((x_deg - field.left_deg) / field.step_deg));
        const int j = static_cast<int>(std::floor((field.top_deg - y_deg) / field.step_deg));
        if (i < 0 || j < 0 || i >= field.width || j >= field.height) continue;
        // Every spot's error counts for the PSNR; its contrast only where the window lies wholly in the
        // evaluated field: at the screen's edge the clean retina itself fades to black and a contrast
        // against it says nothing about the defect.
        bool inside = i >= radius && j >= radius && i + radius < field.width && j + radius < field.height;
        for (int y = j - radius; inside && y <= j + radius; ++y)
          for (int x = i - radius; inside && x <= i + radius; ++x)
            inside = evaluated[static_cast<std::size_t>(y) * field.width + x] != 0;
        if (inside) {
          spots.push_back({n, i, j});
          measured[n] = true;
        }
        for (int y = std::max(0, j - radius); y <= std::min(field.height - 1, j + radius); ++y) {
          for (int x = std::max(0, i - radius); x <= std::min(field.width - 1, i + radius); ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * field.width + x;
            if (!evaluated[p] || slot[p] >= 0) continue;
            slot[p] = static_cast<int>(traced.size());
            traced.push_back({x, y});
          }
        }
      }
      if (traced.empty()) continue;
      const std::vector<Rgba> clean_retina = simulator.retina_at(clean, eye, traced);
      for (std::size_t d = 0; d < displays.size(); ++d) {
        const std::vector<Rgba> retina = simulator.retina_at(*displays[d], eye, traced);
        for (std::size_t t = 0; t < traced.size(); ++t) {
          const double dr = retina[t].r - clean_retina[t].r, dg = retina[t].g - clean_retina[t].g,
                       db = retina[t].b - clean_retina[t].b;
          totals[d].squared_error += dr * dr + dg * dg + db * db;
        }
        for (const Spot& spot : spots) {
          double contrast = 0;
          for (int y = std::max(0, spot.j - radius); y <= std::min(field.height - 1, spot.j + radius); ++y) {
            for (int x = std::max(0, spot.i - radius); x <= std::min(field.width - 1, spot.i + radius); ++x) {
              const int t = slot[static_cast<std::size_t>(y) * field.width + x];
              if (t < 0) continue;
              const double reference = luminance(clean_retina[t]);
              contrast = std::max(
                  contrast, std::abs(luminance(retina[t]) - reference) / std::max(reference, options.contrast_floor));
            }
          }
          totals[d].all.add(contrast);
          (defects[spot.defect].kind == DefectKind::dead ? totals[d].dead : totals[d].stuck).add(contrast);
        }
      }
      for (const auto& p : traced) slot[static_cast<std::size_t>(p[1]) * field.width + p[0]] = -1;
    }
  }

  const auto figures = [&](const Accumulator& a, DefectKind const* kind) {
    DefectSpotFigures f;
    for (std::size_t n = 0; n < defects.size(); ++n)
      if (measured[n] && (!kind || defects[n].kind == *kind)) ++f.count;
    f.worst_spot_contrast = a.worst;
    f.mean_spot_contrast = a.samples ? a.sum / static_cast<double>(a.samples) : 0.0;
    return f;
  };
  std::vector<DefectVisibility> out(displays.size());
  const DefectKind dead = DefectKind::dead, stuck = DefectKind::stuck;
  for (std::size_t d = 0; d < displays.size(); ++d) {
    out[d].all = figures(totals[d].all, nullptr);
    out[d].dead = figures(totals[d].dead, &dead);
    out[d].stuck = figures(totals[d].stuck, &stuck);
    const double mse = evaluated_total ? totals[d].squared_error / (3.0 * static_cast<double>(evaluated_total)) : 0.0;
    out[d].defect_psnr_db = mse > 0.0 ? 10.0 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
  }
  return out;
}

}  // namespace nelf
