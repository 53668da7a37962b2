#pragma once
// Calibration test patterns (`nelf calibrate`): flat stereo views that the compositor turns into
// elemental images like any other content, sized from the profile so that what the user sees
// through the lens array means something:
//   stripes  horizontal stripes in the top half, vertical stripes in the bottom half, each stripe a
//            few display pixels wide: a lens array rotated against the panel breaks them up into
//            tilted pieces and moiré, a wrong pitch scale into steps between elemental images;
//   grid     lines through the screen centre every `grid_spacing_px`, a thicker yellow centre cross
//            and an eye label: both eyes' crosses must fuse (shift, IPD);
//   snellen  rows of Sloan letters labelled 20/x, sized so that the 20/20 row subtends 5 arcmin at
//            the virtual screen's distance (prescription, gap);
//   white    a flat white field: seams between elemental images and the lit area.
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/image.hpp"
#include "optics/profile.hpp"

namespace nelf {

enum class TestPattern { stripes, grid, snellen, white };

// "stripes", "grid", "snellen", "white"; nullopt for anything else.
std::optional<TestPattern> parse_test_pattern(std::string_view name);
std::string test_pattern_name(TestPattern pattern);
const std::vector<std::string>& test_pattern_names();

// A pattern that cannot be drawn for this profile (e.g. a Snellen chart for a device whose screen
// size is unknown, or a missing font). what() is one line saying what to do.
class TestPatternError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The view size and the virtual screen the views are shown on, and the pattern sizes derived from
// them. All sizes in view pixels.
struct PatternGeometry {
  int width = 1920;
  int height = 1080;
  double screen_width_mm = 0.0;       // width of the virtual screen the view fills (0 = unknown)
  double screen_distance_mm = 0.0;    // its distance from the eye
  double display_pixel_texels = 1.0;  // view pixels one display pixel covers on that screen (>= 1)
  int stripe_period_px = 8;           // one white and one black stripe
  int grid_spacing_px = 120;
  int line_width_px = 1;
  friend bool operator==(const PatternGeometry&, const PatternGeometry&) = default;
};

// The geometry of `profile`'s virtual screen for views of `width`×`height` (display aspect
// width/height): the lens-array mapping's screen (optics/mapping), or for a stock device the
// panel magnified by its [magnifier] (screen width unknown without one). Stripes are three display
// pixels wide, grid lines one display pixel, 16 grid cells across.
PatternGeometry pattern_geometry(const Profile& profile, int width = 1920, int height = 1080);

// Letter height in view pixels of the Snellen row 20/`denominator`: 5 arcmin × denominator/20 at
// the screen distance. Throws TestPatternError when the screen width is unknown.
double snellen_letter_height_px(const PatternGeometry& geometry, int denominator);

struct SnellenRow {
  int denominator = 20;           // the row is 20/denominator
  double letter_height_px = 0.0;  // exact height of a letter
  int top_px = 0;                 // top edge of the letters
  std::string letters;            // Sloan letters
};

// The rows that fit the view, largest first: from 20/800 down to 20/10, leaving out rows whose
// letters would be smaller than 3 view pixels or taller than a sixth of the view; the chart is
// centred vertically. Each row is labelled "20/x" at the left, its label's cap height
// snellen_label_height_px.
double snellen_label_height_px(double letter_height_px);
std::vector<SnellenRow> snellen_layout(const PatternGeometry& geometry);

// Both eyes' views (display aspect width/height). Throws TestPatternError as above.
StereoPair make_test_pattern(TestPattern pattern, const PatternGeometry& geometry);

}  // namespace nelf
