#include "inputs/test_patterns.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/chart_style.hpp"
#include "core/image_library.hpp"
#include "optics/mapping.hpp"
#include "optics/optics.hpp"

namespace nelf {

namespace {

constexpr std::array<int, 11> kSnellenDenominators = {800, 400, 200, 100, 70, 50, 40, 30, 25, 20, 10};
// Sloan letters, in the order each row takes them from (a fixed, readable sequence, not random, so
// that tests and users see the same chart every time).
constexpr std::string_view kSloanLetters = "CDHKNORSVZ";

const Rgba kWhite{1.f, 1.f, 1.f, 1.f};
const Rgba kBlack{0.f, 0.f, 0.f, 1.f};
const Rgba kYellow{1.f, 0.9f, 0.f, 1.f};

void fill_rect(Image& image, int x0, int y0, int x1, int y1, Rgba colour) {
  x0 = std::clamp(x0, 0, image.width()), x1 = std::clamp(x1, 0, image.width());
  y0 = std::clamp(y0, 0, image.height()), y1 = std::clamp(y1, 0, image.height());
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) image.at(x, y) = colour;
}

// Text drawn with OpenImageIO on a float RGB canvas, then copied into an Image. Text heights are
// cap heights (the height of "H"), measured on the font itself, so that a Snellen letter of
// height h is h pixels tall whatever the font's em box.
class TextCanvas {
 public:
  TextCanvas(int width, int height)
      : width_(width),
        buffer_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height)),
        font_(chart::font()) {
    const auto h = image_library::text_size("H", kProbeSize, font_);
    if (!h || h->height() <= 0) fail("cannot measure text");
    cap_per_em_ = static_cast<double>(h->height()) / kProbeSize;
  }

  // Draws `text` with its cap height `cap_px`, top edge at `top`, centred on `x` or starting there.
  void draw(double x, int top, const std::string& text, double cap_px, bool centred) {
    const int size = std::max(1, static_cast<int>(std::lround(cap_px / cap_per_em_)));
    const float coverage[1] = {1.f};
    using image_library::AlignX;
    try {
      image_library::render_text({.values = buffer_.data(),
                                  .width = width_,
                                  .height = static_cast<int>(buffer_.size() / static_cast<std::size_t>(width_)),
                                  .channels = 1},
                                 static_cast<int>(std::lround(x)), top, text, size, font_, coverage,
                                 centred ? AlignX::center : AlignX::left, image_library::AlignY::top);
    } catch (const image_library::ImageLibraryError& e) {
      fail(e.what());
    }
  }

  // Adds the drawn text (antialiased) onto `image` in `colour`.
  void composite_onto(Image& image, Rgba colour) const {
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x) {
        const float a =
            buffer_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)];
        if (a <= 0.f) continue;
        Rgba& p = image.at(x, y);
        p.r = p.r * (1.f - a) + colour.r * a;
        p.g = p.g * (1.f - a) + colour.g * a;
        p.b = p.b * (1.f - a) + colour.b * a;
      }
  }

 private:
  static constexpr int kProbeSize = 200;
  [[noreturn]] void fail(const std::string& why) const {
    throw TestPatternError(fmt::format("cannot draw the pattern's text with font '{}' (install fonts-dejavu-core): {}",
                                       font_, why.empty() ? "unknown OpenImageIO error" : why));
  }
  int width_;
  std::vector<float> buffer_;  // the text's coverage, one float a pixel
  std::string font_;
  double cap_per_em_ = 0.73;
};

Image stripes(const PatternGeometry& g) {
  Image image(g.width, g.height);
  const int half = std::max(1, g.stripe_period_px / 2);
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      // Top half: horizontal stripes (they vary along y); bottom half: vertical stripes.
      const int along = y < g.height / 2 ? y : x;
      image.at(x, y) = (along / half) % 2 == 0 ? kWhite : kBlack;
    }
  return image;
}

// Lines through the centre every spacing pixels, each line_width wide and centred on its position.
Image grid(const PatternGeometry& g, Eye eye) {
  Image image(g.width, g.height);
  const int cx = g.width / 2, cy = g.height / 2, lw = g.line_width_px, s = g.grid_spacing_px;
  for (int k = -(cx / s) - 1; k <= cx / s + 1; ++k) {
    const int x = cx + k * s - lw / 2;
    fill_rect(image, x, 0, x + lw, g.height, kWhite);
  }
  for (int k = -(cy / s) - 1; k <= cy / s + 1; ++k) {
    const int y = cy + k * s - lw / 2;
    fill_rect(image, 0, y, g.width, y + lw, kWhite);
  }
  // The centre cross: twice as thick, yellow, half a cell each way.
  fill_rect(image, cx - lw, cy - s / 2, cx + lw, cy + s / 2, kYellow);
  fill_rect(image, cx - s / 2, cy - lw, cx + s / 2, cy + lw, kYellow);
  TextCanvas text(g.width, g.height);
  const int cell_x = cx - (cx / s) * s, cell_y = cy - (cy / s) * s;  // top-left full cell
  text.draw(cell_x + s / 2.0, cell_y + s / 4, eye == Eye::left ? "L" : "R", s / 2.0, true);
  text.composite_onto(image, kYellow);
  return image;
}

Image snellen(const PatternGeometry& g) {
  Image image(g.width, g.height);
  TextCanvas text(g.width, g.height);
  const double label_column = 0.14 * g.width;
  for (const SnellenRow& row : snellen_layout(g)) {
    const double h = row.letter_height_px;
    const auto n = static_cast<double>(row.letters.size());
    // Sloan letters are as wide as tall; a letter's width between letters.
    const double first_centre = label_column + (g.width - label_column - (2.0 * n - 1.0) * h) / 2.0 + h / 2.0;
    for (std::size_t i = 0; i < row.letters.size(); ++i)
      text.draw(first_centre + 2.0 * h * static_cast<double>(i), row.top_px, std::string(1, row.letters[i]), h, true);
    const double label_h = snellen_label_height_px(h);
    text.draw(0.02 * g.width, row.top_px + static_cast<int>(std::lround((h - label_h) / 2.0)),
              fmt::format("20/{}", row.denominator), label_h, false);
  }
  text.composite_onto(image, kWhite);
  return image;
}

}  // namespace

std::optional<TestPattern> parse_test_pattern(std::string_view name) {
  for (TestPattern p : {TestPattern::stripes, TestPattern::grid, TestPattern::snellen, TestPattern::white})
    if (name == test_pattern_name(p)) return p;
  return std::nullopt;
}

std::string test_pattern_name(TestPattern pattern) {
  switch (pattern) {
    case TestPattern::stripes:
      return "stripes";
    case TestPattern::grid:
      return "grid";
    case TestPattern::snellen:
      return "snellen";
    case TestPattern::white:
      return "white";
  }
  return "?";
}

const std::vector<std::string>& test_pattern_names() {
  static const std::vector<std::string> names = {"stripes", "grid", "snellen", "white"};
  return names;
}

PatternGeometry pattern_geometry(const Profile& profile, int width, int height) {
  if (width < 64 || height < 64) throw std::invalid_argument("pattern_geometry: views smaller than 64x64");
  PatternGeometry g;
  g.width = width;
  g.height = height;
  const EyeMapping m = make_eye_mapping(profile, Eye::left, static_cast<double>(width) / height);
  if (m.has_lens_array) {
    g.screen_width_mm = m.screen_size_mm.x;
    g.screen_distance_mm = m.render_distance_mm;
  } else if (profile.magnifier) {
    // The panel's picture magnified by the single lens (Eq. 2), seen at the virtual image distance.
    g.screen_width_mm =
        m.view_size_mm.x * optics::magnification(profile.magnifier->focal_length_mm, profile.viewing.virtual_image_mm,
                                                 profile.viewing.eye_relief_mm);
    g.screen_distance_mm = profile.viewing.virtual_image_mm;
  }
  g.display_pixel_texels = std::max(1.0, pixel_footprint_uv(m).x * width);
  g.line_width_px = std::max(1, static_cast<int>(std::lround(g.display_pixel_texels)));
  g.stripe_period_px = 2 * std::max(2, static_cast<int>(std::lround(3.0 * g.display_pixel_texels)));
  g.grid_spacing_px = std::max(width / 16, 8 * g.line_width_px);
  return g;
}

double snellen_letter_height_px(const PatternGeometry& g, int denominator) {
  if (!(g.screen_width_mm > 0.0) || !(g.screen_distance_mm > 0.0))
    throw TestPatternError(
        "the Snellen chart needs the virtual screen's size: this profile has no [lens_array] and no [magnifier] "
        "(add [magnifier] width_mm and focal_length_mm)");
  // 20/20: the letter subtends 5 arcmin; 20/x letters are x/20 times as large.
  const double angle = 5.0 / 60.0 * std::numbers::pi / 180.0 * denominator / 20.0;
  const double height_mm = 2.0 * g.screen_distance_mm * std::tan(angle / 2.0);
  return height_mm / g.screen_width_mm * g.width;
}

double snellen_label_height_px(double letter_height_px) { return std::clamp(0.5 * letter_height_px, 12.0, 40.0); }

std::vector<SnellenRow> snellen_layout(const PatternGeometry& g) {
  std::vector<SnellenRow> rows;
  const double margin = 0.04 * g.height;
  double top = margin;
  std::size_t next_letter = 0;
  for (int denominator : kSnellenDenominators) {
    const double h = snellen_letter_height_px(g, denominator);
    if (h > g.height / 6.0) continue;
    if (h < 3.0) break;
    // A row is as tall as its letters or its label, whichever is taller.
    const double row_height = std::max(h, snellen_label_height_px(h));
    if (top + row_height > g.height - margin) break;
    SnellenRow row;
    row.denominator = denominator;
    row.letter_height_px = h;
    row.top_px = static_cast<int>(std::lround(top + (row_height - h) / 2.0));
    const double usable = 0.8 * g.width;
    const int count = std::clamp(static_cast<int>((usable / h + 1.0) / 2.0), 1, 5);
    for (int i = 0; i < count; ++i) row.letters += kSloanLetters[next_letter++ % kSloanLetters.size()];
    rows.push_back(row);
    top += row_height + std::max(0.6 * h, 10.0);
  }
  // The chart centred vertically in the view.
  if (!rows.empty()) {
    const double used = rows.back().top_px + rows.back().letter_height_px - rows.front().top_px;
    const int offset = static_cast<int>(std::lround((g.height - used) / 2.0)) - rows.front().top_px;
    if (offset > 0)
      for (auto& row : rows) row.top_px += offset;
  }
  return rows;
}

StereoPair make_test_pattern(TestPattern pattern, const PatternGeometry& g) {
  StereoPair views;
  const double aspect = static_cast<double>(g.width) / g.height;
  switch (pattern) {
    case TestPattern::stripes:
      views.left.image = stripes(g);
      views.right.image = views.left.image;
      break;
    case TestPattern::grid:
      views.left.image = grid(g, Eye::left);
      views.right.image = grid(g, Eye::right);
      break;
    case TestPattern::snellen:
      views.left.image = snellen(g);
      views.right.image = views.left.image;
      break;
    case TestPattern::white:
      views.left.image = Image(g.width, g.height);
      for (Rgba& p : views.left.image.pixels()) p = kWhite;
      views.right.image = views.left.image;
      break;
  }
  views.left.display_aspect = views.right.display_aspect = aspect;
  return views;
}

}  // namespace nelf
