// Planning the compensation of dead and stuck pixels (optics/defect_compensation.hpp, docs/defects.md).
//
// The retina model the plan is fitted to is the eye simulator's (DESIGN.md §5) with the eye focused on
// the emulated screen. A retinal point looking at screen point v collects, through each lens c, the
// display point s*(c) = c + (v − c) d_l/(d_r − d_e) — the pixel of c's elemental image showing v —
// from the pupil points whose ray to v crosses c's aperture: a square on the pupil plane, centred on
// (c − v d_e/d_r) d_r/(d_r − d_e), of side w_l d_r/(d_r − d_e). These squares tile the pupil plane, so
// the pupil's share of lens c is the fraction of the pupil disc its square covers (a_c(q) for the
// pupil at q). Near v the display is read bilinearly, so a change δ at a pixel u pixels away from s*
// shows on the retina as δ a_c(q) T(x − u), T the tent of one pixel per axis, x the retinal offset in
// display pixels (one display pixel is one footprint on the screen, for every lens).
//
// The defect d (in lens c_d, at v's own pixel) takes Δ a_d(q) T(x) away. Its bundle is, for each lit
// lens near c_d, the 2×2 pixels around s*(c): they reproduce both where the light lands (sub-pixel)
// and through which part of the pupil it enters. The weights minimise
//   Σ_q ∫ (Σ_i w_i a_{c_i}(q) T(x − u_i) − a_d(q) T(x))² dx,   0 ≤ w_i ≤ 1,
// which separates into a pupil Gram matrix per lens pair times the autocorrelation of the tent
// (a cubic B-spline), so each defect is a small dense box-constrained quadratic problem.
#include "optics/defect_compensation.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_set>

namespace nelf {

namespace {

// Lenses within this distance (in lens pitches) of the defect's lens make up its bundle: two pitches
// reach every beam a 4 mm pupil sees beside the defect's own for the hmz-t1 geometry.
constexpr double bundle_radius_lenses = 2.0;
// A share may at most double the light of its pixel's part of the bundle (w ≤ 1): beyond that the
// correction of one pupil position spoils the others and the clipping grows.
constexpr double max_weight = 1.0;
// Shares below this are dropped after solving: they change the retina by less than a thousandth of
// the defect's own error and cost per-frame work.
constexpr double min_weight = 1e-3;

Vec2 rotate(Vec2 v, double c, double s) { return {c * v.x - s * v.y, s * v.x + c * v.y}; }

// Fraction of the disc (centre q, radius r) that the axis-aligned square (centre p, half side h) covers,
// integrated over x in slices (the chord lengths, exact per slice).
double disc_square_fraction(Vec2 q, double r, Vec2 p, double h) {
  const double x0 = std::max(p.x - h, q.x - r), x1 = std::min(p.x + h, q.x + r);
  if (x1 <= x0 || std::abs(p.y - q.y) >= h + r) return 0.0;
  constexpr int slices = 32;
  const double dx = (x1 - x0) / slices;
  double area = 0.0;
  for (int k = 0; k < slices; ++k) {
    const double x = x0 + (k + 0.5) * dx - q.x;
    const double half_chord = std::sqrt(std::max(0.0, r * r - x * x));
    const double overlap = std::min(q.y + half_chord, p.y + h) - std::max(q.y - half_chord, p.y - h);
    if (overlap > 0.0) area += overlap * dx;
  }
  return area / (3.14159265358979323846 * r * r);
}

// ∫ T(x) T(x − t) dx for the tent T(x) = max(0, 1 − |x|): the cubic B-spline.
double tent_autocorrelation(double t) {
  t = std::abs(t);
  if (t < 1.0) return 2.0 / 3.0 - t * t + t * t * t / 2.0;
  if (t < 2.0) return (2.0 - t) * (2.0 - t) * (2.0 - t) / 6.0;
  return 0.0;
}

double spatial_overlap(Vec2 a, Vec2 b) { return tent_autocorrelation(a.x - b.x) * tent_autocorrelation(a.y - b.y); }

// Continuous pixel coordinate (pixel (i, j) has its centre at (i + ½, j + ½)) of display position s:
// the inverse of display_position_mm.
Vec2 pixel_coordinate(const EyeMapping& m, Vec2 s) {
  return {s.x / m.pixel_pitch_mm.x + m.panel[0] / 2.0 + m.shift_px.x,
          m.panel[1] / 2.0 + m.shift_px.y - s.y / m.pixel_pitch_mm.y};
}

struct LensIndex {
  int m = 0, n = 0;
  friend bool operator==(const LensIndex&, const LensIndex&) = default;
};

LensIndex lens_index(const EyeMapping& m, Vec2 centre) {
  const Vec2 q =
      rotate({centre.x - m.lattice_offset_mm.x, centre.y - m.lattice_offset_mm.y}, m.rotation_cos, -m.rotation_sin);
  return {static_cast<int>(std::lround(q.x / m.lens_pitch_mm)), static_cast<int>(std::lround(q.y / m.lens_pitch_mm))};
}

Vec2 lens_centre(const EyeMapping& m, LensIndex lens) {
  const Vec2 c = rotate({lens.m * m.lens_pitch_mm, lens.n * m.lens_pitch_mm}, m.rotation_cos, m.rotation_sin);
  return {m.lattice_offset_mm.x + c.x, m.lattice_offset_mm.y + c.y};
}

// Whether screen point v (mm) is on the emulated screen.
bool on_screen(const EyeMapping& m, Vec2 v) {
  return std::abs(v.x - m.screen_centre_mm.x) <= m.screen_size_mm.x / 2.0 &&
         std::abs(v.y - m.screen_centre_mm.y) <= m.screen_size_mm.y / 2.0;
}

bool lit_lens(const EyeMapping& m, LensIndex lens) {
  return lens.m >= m.first_lens[0] && lens.m < m.first_lens[0] + m.lenses[0] && lens.n >= m.first_lens[1] &&
         lens.n < m.first_lens[1] + m.lenses[1];
}

// One candidate pixel of a bundle: which lens it belongs to (index into the bundle's lenses) and its
// offset from the exact position s*(c), in pixels.
struct Candidate {
  int x = 0, y = 0;
  int lens = 0;
  Vec2 offset_px;
};

struct BundleLens {
  LensIndex index;
  Vec2 centre;
};

// The lenses of the bundle of the pixel whose chief ray meets the screen at v (from lens `own`) and
// the pixels near s*(c) in each, `own` itself excluded. Pixels must lie on the panel, in their lens's
// elemental image and show part of the view.
void bundle_of(const EyeMapping& m, LensIndex own, Vec2 v, std::vector<BundleLens>& lenses,
               std::vector<Candidate>& candidates) {
  lenses.clear();
  candidates.clear();
  const double k = (m.render_distance_mm - m.eye_relief_mm) / m.gap_mm;
  const int reach = static_cast<int>(std::floor(bundle_radius_lenses));
  for (int dn = -reach; dn <= reach; ++dn) {
    for (int dm = -reach; dm <= reach; ++dm) {
      if ((dm == 0 && dn == 0) || dm * dm + dn * dn > bundle_radius_lenses * bundle_radius_lenses) continue;
      const LensIndex lens{own.m + dm, own.n + dn};
      if (!lit_lens(m, lens)) continue;
      const Vec2 c = lens_centre(m, lens);
      const Vec2 exact = pixel_coordinate(m, {c.x + (v.x - c.x) / k, c.y + (v.y - c.y) / k});
      const int x0 = static_cast<int>(std::floor(exact.x - 0.5)), y0 = static_cast<int>(std::floor(exact.y - 0.5));
      const int slot = static_cast<int>(lenses.size());
      bool any = false;
      for (int y = y0; y <= y0 + 1; ++y) {
        for (int x = x0; x <= x0 + 1; ++x) {
          if (x < 0 || y < 0 || x >= m.panel[0] || y >= m.panel[1]) continue;
          const Vec2 s = display_position_mm(m, x + 0.5, y + 0.5);
          const auto owner = owner_lens_centre(m, s);
          if (!owner || !(lens_index(m, *owner) == lens) || !view_coordinate(m, s)) continue;
          candidates.push_back({x, y, slot, {x + 0.5 - exact.x, y + 0.5 - exact.y}});
          any = true;
        }
      }
      if (any) lenses.push_back({lens, c});
    }
  }
}

// min ½ wᵀGw − hᵀw over 0 ≤ w ≤ max_weight by cyclic coordinate descent (G symmetric positive
// definite: it converges to the unique minimum; a few dozen sweeps reach it to well below min_weight).
void solve_box_qp(const std::vector<double>& gram, const std::vector<double>& rhs, std::vector<double>& w) {
  const std::size_t n = rhs.size();
  w.assign(n, 0.0);
  std::vector<double> gradient(rhs.size());
  for (std::size_t i = 0; i < n; ++i) gradient[i] = -rhs[i];  // G w − h at w = 0
  for (int sweep = 0; sweep < 200; ++sweep) {
    double largest_step = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double diagonal = gram[i * n + i];
      if (!(diagonal > 0.0)) continue;
      const double updated = std::clamp(w[i] - gradient[i] / diagonal, 0.0, max_weight);
      const double step = updated - w[i];
      if (step == 0.0) continue;
      w[i] = updated;
      for (std::size_t j = 0; j < n; ++j) gradient[j] += gram[j * n + i] * step;
      largest_step = std::max(largest_step, std::abs(step));
    }
    if (largest_step < 1e-5) break;
  }
}

// The pupil plane squares of lens c for screen point v (see the top of the file), in the lattice's
// frame: centre and half side.
struct PupilSquare {
  Vec2 centre;
  double half_side = 0;
};

PupilSquare pupil_square(const EyeMapping& m, Vec2 c, Vec2 v) {
  const double d_r = m.render_distance_mm, d_e = m.eye_relief_mm;
  const double scale = d_r / (d_r - d_e);
  const Vec2 centre{(c.x - v.x * d_e / d_r) * scale, (c.y - v.y * d_e / d_r) * scale};
  return {rotate(centre, m.rotation_cos, -m.rotation_sin), m.lens_pitch_mm / 2.0 * scale};
}

}  // namespace

double eye_box_width_mm(const EyeMapping& m) {
  if (!m.has_lens_array) return 0.0;
  const double d_r = m.render_distance_mm, d_e = m.eye_relief_mm, d_l = m.gap_mm;
  return std::abs(d_r / (d_r - d_e) * m.lens_pitch_mm - (d_e + d_l) / d_l * m.lens_pitch_mm);
}

std::vector<Vec2> eye_box_pupil_positions(const EyeMapping& m, double pupil_mm, int per_axis) {
  const double span = std::max(0.0, eye_box_width_mm(m) - pupil_mm);
  std::vector<Vec2> positions;
  if (per_axis < 1) return positions;
  for (int j = 0; j < per_axis; ++j)
    for (int i = 0; i < per_axis; ++i)
      positions.push_back(per_axis == 1
                              ? Vec2{0.0, 0.0}
                              : Vec2{span * (i / (per_axis - 1.0) - 0.5), span * (j / (per_axis - 1.0) - 0.5)});
  return positions;
}

std::vector<std::array<int, 2>> defect_bundle_pixels(const EyeMapping& m, int x, int y) {
  std::vector<std::array<int, 2>> pixels;
  if (!m.has_lens_array) return pixels;
  const Vec2 s = display_position_mm(m, x + 0.5, y + 0.5);
  const auto own = owner_lens_centre(m, s);
  if (!own || !view_coordinate(m, s)) return pixels;
  const double k = (m.render_distance_mm - m.eye_relief_mm) / m.gap_mm;
  const Vec2 v{own->x + (s.x - own->x) * k, own->y + (s.y - own->y) * k};
  std::vector<BundleLens> lenses;
  std::vector<Candidate> candidates;
  bundle_of(m, lens_index(m, *own), v, lenses, candidates);
  for (const Candidate& c : candidates) pixels.push_back({c.x, c.y});
  return pixels;
}

std::optional<Vec2> defect_screen_point(const EyeMapping& m, const PixelDefect& d) {
  if (!m.has_lens_array) return std::nullopt;
  const Vec2 s = display_position_mm(m, d.x + 0.5, d.y + 0.5);
  const bool lit = view_coordinate(m, s).has_value();
  // A stuck pixel outside the lit elemental images is sent black but shows its value, through the
  // lens in front of it, to a screen point that lit pixels of other lenses show too: from the eye
  // box's edge its beam enters the pupil (a stuck white pixel beside the lit block put a 19.6 % spot
  // on another defect's window, docs/defects.md). A dead one there shows what it is sent.
  if (!lit && d.kind != DefectKind::stuck) return std::nullopt;
  const Vec2 c = lens_centre_in_front(m, s);
  const double k = (m.render_distance_mm - m.eye_relief_mm) / m.gap_mm;
  const Vec2 v{c.x + (s.x - c.x) * k, c.y + (s.y - c.y) * k};
  if (!lit && !on_screen(m, v)) return std::nullopt;
  return v;
}

EyeDefectPlan plan_defect_compensation(const EyeMapping& mapping, const DefectMap& map,
                                       const DefectPlanOptions& options) {
  EyeDefectPlan plan;
  plan.eye = mapping.eye;
  plan.panel = mapping.panel;
  const auto key = [&](int x, int y) {
    return static_cast<std::int64_t>(y) * static_cast<std::int64_t>(mapping.panel[0]) + x;
  };
  std::unordered_set<std::int64_t> defective;
  for (const PixelDefect& d : map.defects)
    if (d.eye == mapping.eye) defective.insert(key(d.x, d.y));

  const std::vector<Vec2> pupils =
      mapping.has_lens_array ? eye_box_pupil_positions(mapping, options.pupil_mm, std::max(1, options.eye_box_grid))
                             : std::vector<Vec2>{};
  const double pupil_radius = options.pupil_mm / 2.0;
  // The pupil positions in the lattice's frame, where the lens squares are axis-aligned.
  std::vector<Vec2> pupils_in_lattice;
  for (const Vec2& q : pupils) pupils_in_lattice.push_back(rotate(q, mapping.rotation_cos, -mapping.rotation_sin));

  std::vector<BundleLens> lenses;
  std::vector<Candidate> candidates;
  std::vector<double> coverage, defect_coverage, lens_gram, defect_lens, gram, rhs, weights;
  for (const PixelDefect& d : map.defects) {
    if (d.eye != mapping.eye) continue;
    const Vec2 s = display_position_mm(mapping, d.x + 0.5, d.y + 0.5);
    if (!mapping.has_lens_array) {  // one pixel per screen point: nothing else shows it
      if (view_coordinate(mapping, s))
        ++plan.uncompensable;
      else
        ++plan.outside_lit;
      continue;
    }
    const std::optional<Vec2> screen_point = defect_screen_point(mapping, d);
    if (!screen_point) {
      ++plan.outside_lit;
      continue;
    }
    const Vec2 v = *screen_point;
    const Vec2 own = lens_centre_in_front(mapping, s);
    bundle_of(mapping, lens_index(mapping, own), v, lenses, candidates);
    std::erase_if(candidates, [&](const Candidate& c) { return defective.contains(key(c.x, c.y)); });

    // The pupil's share of each lens at each pupil position; the defect's own lens first.
    const std::size_t q_count = pupils.size(), lens_count = lenses.size();
    const auto share = [&](Vec2 centre, std::size_t q) {
      const PupilSquare sq = pupil_square(mapping, centre, v);
      return disc_square_fraction(pupils_in_lattice[q], pupil_radius, sq.centre, sq.half_side);
    };
    defect_coverage.resize(q_count);
    double defect_seen = 0.0;
    for (std::size_t q = 0; q < q_count; ++q) defect_seen += defect_coverage[q] = share(own, q);
    if (defect_seen <= 0.0) continue;  // no pupil position of the eye box sees it: nothing to make up
    if (candidates.empty()) {
      ++plan.uncompensable;
      continue;
    }
    coverage.assign(lens_count * q_count, 0.0);
    for (std::size_t l = 0; l < lens_count; ++l)
      for (std::size_t q = 0; q < q_count; ++q) coverage[l * q_count + q] = share(lenses[l].centre, q);
    lens_gram.assign(lens_count * lens_count, 0.0);
    defect_lens.assign(lens_count, 0.0);
    for (std::size_t a = 0; a < lens_count; ++a) {
      for (std::size_t q = 0; q < q_count; ++q) defect_lens[a] += coverage[a * q_count + q] * defect_coverage[q];
      for (std::size_t b = a; b < lens_count; ++b) {
        double sum = 0.0;
        for (std::size_t q = 0; q < q_count; ++q) sum += coverage[a * q_count + q] * coverage[b * q_count + q];
        lens_gram[a * lens_count + b] = lens_gram[b * lens_count + a] = sum;
      }
    }
    const std::size_t n = candidates.size();
    gram.assign(n * n, 0.0);
    rhs.assign(n, 0.0);
    double trace = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const Candidate& ci = candidates[i];
      rhs[i] = defect_lens[ci.lens] * spatial_overlap(ci.offset_px, {0.0, 0.0});
      for (std::size_t j = i; j < n; ++j) {
        const Candidate& cj = candidates[j];
        gram[i * n + j] = gram[j * n + i] =
            lens_gram[ci.lens * lens_count + cj.lens] * spatial_overlap(ci.offset_px, cj.offset_px);
      }
      trace += gram[i * n + i];
    }
    // A faint ridge keeps the problem strictly convex where two candidates look alike (the same lens
    // seen from no pupil position, neighbouring pixels): the smallest-norm spread wins.
    for (std::size_t i = 0; i < n; ++i) gram[i * n + i] += 1e-6 * trace / static_cast<double>(n);
    solve_box_qp(gram, rhs, weights);

    DefectCorrection correction{d, {}};
    for (std::size_t i = 0; i < n; ++i)
      if (weights[i] >= min_weight)
        correction.shares.push_back({candidates[i].x, candidates[i].y, static_cast<float>(weights[i])});
    if (correction.shares.empty()) {
      ++plan.uncompensable;
      continue;
    }
    plan.corrections.push_back(std::move(correction));
  }
  return plan;
}

}  // namespace nelf
