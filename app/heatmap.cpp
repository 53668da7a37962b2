#include "app/heatmap.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <system_error>

#include "app/commands.hpp"
#include "core/chart_style.hpp"
#include "core/image_library.hpp"
#include "hmz_output/image_sink.hpp"

namespace nelf::app {

namespace {

using Colour = chart::Rgb;

using chart::viridis;

// A white float RGB raster with filled rectangles and text (OpenImageIO's).
class Canvas {
 public:
  Canvas(int width, int height)
      : width_(width),
        height_(height),
        pixels_(static_cast<std::size_t>(width) * height * 3, 1.f),
        font_(chart::font()) {}
  void rectangle(int x0, int y0, int x1, int y1, const Colour& c) {
    for (int y = std::max(y0, 0); y < std::min(y1, height_); ++y)
      for (int x = std::max(x0, 0); x < std::min(x1, width_); ++x)
        std::copy(c.begin(), c.end(), pixels_.begin() + (static_cast<std::ptrdiff_t>(y) * width_ + x) * 3);
  }
  void text(int x, int y, const std::string& s, int size, image_library::AlignX align_x,
            image_library::AlignY align_y = image_library::AlignY::center, const Colour& c = {0.f, 0.f, 0.f}) {
    try {
      image_library::render_text({.values = pixels_.data(), .width = width_, .height = height_, .channels = 3}, x, y, s,
                                 size, font_, c, align_x, align_y);
    } catch (const image_library::ImageLibraryError& e) {
      throw UserError(
          fmt::format("cannot draw the heatmap labels ({}): install a TrueType font, e.g. Debian's "
                      "fonts-dejavu-core",
                      e.what()));
    }
  }
  image_library::Picture picture() const {
    return {.values = pixels_.data(), .width = width_, .height = height_, .channels = 3, .pixel_stride = 3};
  }

 private:
  int width_, height_;
  std::vector<float> pixels_;
  std::string font_;
};

}  // namespace

void write_heatmap_png(const Heatmap& map, const std::filesystem::path& path) {
  using AlignX = image_library::AlignX;
  using AlignY = image_library::AlignY;
  const int rows = static_cast<int>(map.y_ticks.size()), columns = static_cast<int>(map.x_ticks.size());
  if (rows == 0 || columns == 0 || static_cast<int>(map.values.size()) != rows)
    throw std::invalid_argument("heatmap: ticks and values disagree");

  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& row : map.values) {
    if (static_cast<int>(row.size()) != columns) throw std::invalid_argument("heatmap: ragged values");
    for (double v : row)
      if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  if (!(lo < hi)) lo = std::isfinite(lo) ? lo - 1 : 0, hi = std::isfinite(hi) ? hi + 1 : 1;

  for (const HeatmapLine& line : map.lines)
    if (static_cast<int>(line.column_position.size()) != rows)
      throw std::invalid_argument("heatmap: a line without one position per row");

  constexpr int cell_w = 46, cell_h = 34, top = 60, bar_gap = 30, bar_w = 24, right = 90;
  const int bottom = map.note.empty() ? 80 : 104;
  // Room for the longest row label at 14 px (about 8 px a character in DejaVu Sans), 130 px at least.
  std::size_t longest = 0;
  for (const std::string& tick : map.y_ticks) longest = std::max(longest, tick.size());
  const int left = std::max(130, 16 + static_cast<int>(longest) * 8);
  const int plot_w = columns * cell_w, plot_h = rows * cell_h;
  Canvas canvas(left + plot_w + bar_gap + bar_w + right, top + plot_h + bottom);

  canvas.text(left + plot_w / 2, top / 2, map.title, 20, AlignX::center);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      const double v = map.values[r][c];
      const int x0 = left + c * cell_w, y0 = top + r * cell_h;
      const Colour colour = std::isfinite(v) ? viridis((v - lo) / (hi - lo)) : Colour{0.7f, 0.7f, 0.7f};
      canvas.rectangle(x0, y0, x0 + cell_w, y0 + cell_h, colour);
      // Dark text on the light (yellow-green) end of the map, white on the dark end.
      const double luminance = 0.2126 * colour[0] + 0.7152 * colour[1] + 0.0722 * colour[2];
      const Colour ink = luminance > 0.45 ? Colour{0.f, 0.f, 0.f} : Colour{1.f, 1.f, 1.f};
      canvas.text(x0 + cell_w / 2, y0 + cell_h / 2,
                  std::isfinite(v) ? fmt::format("{:.{}f}", v, map.value_decimals) : "-", 14, AlignX::center,
                  AlignY::center, ink);
    }
    canvas.text(left - 8, top + r * cell_h + cell_h / 2, map.y_ticks[r], 14, AlignX::right);
  }
  for (int c = 0; c < columns; ++c)
    canvas.text(left + c * cell_w + cell_w / 2, top + plot_h + 14, map.x_ticks[c], 13, AlignX::center);
  canvas.text(left + plot_w / 2, top + plot_h + 50, map.x_label, 16, AlignX::center);
  if (!map.note.empty()) canvas.text(left + plot_w / 2, top + plot_h + 80, map.note, 14, AlignX::center);

  // Lines: a 3 px stroke per row at its position (clamped to the plot's edges), joined at the rows'
  // common border; a row without a position (NaN) breaks the line.
  for (const HeatmapLine& line : map.lines) {
    const auto x_at = [&](double position) {
      const double clamped = std::clamp(position, -0.5, columns - 0.5);
      return left + static_cast<int>(std::lround((clamped + 0.5) * cell_w));
    };
    for (int r = 0; r < rows; ++r) {
      const double position = line.column_position[r];
      if (!std::isfinite(position)) continue;
      const int x = x_at(position), y0 = top + r * cell_h;
      canvas.rectangle(x - 1, y0 - 1, x + 2, y0 + cell_h + 2, line.colour);
      if (r + 1 < rows && std::isfinite(line.column_position[r + 1])) {
        const int next = x_at(line.column_position[r + 1]);
        canvas.rectangle(std::min(x, next) - 1, y0 + cell_h - 1, std::max(x, next) + 2, y0 + cell_h + 2, line.colour);
      }
    }
  }
  canvas.text(10, top - 14, map.y_label, 16, AlignX::left);

  // Colour bar: top = highest value.
  const int bar_x = left + plot_w + bar_gap;
  for (int y = 0; y < plot_h; ++y)
    canvas.rectangle(bar_x, top + y, bar_x + bar_w, top + y + 1, viridis(1.0 - (y + 0.5) / plot_h));
  constexpr int bar_ticks = 5;
  for (int k = 0; k < bar_ticks; ++k) {
    const double f = static_cast<double>(k) / (bar_ticks - 1);
    const int y = top + static_cast<int>(std::lround((1.0 - f) * (plot_h - 1)));
    canvas.rectangle(bar_x + bar_w, y, bar_x + bar_w + 5, y + 1, {0.f, 0.f, 0.f});
    canvas.text(bar_x + bar_w + 8, y, fmt::format("{:.1f}", lo + f * (hi - lo)), 13, AlignX::left);
  }
  canvas.text(bar_x + bar_w / 2, top - 14, map.value_label, 16, AlignX::center);

  try {
    write_file_atomically(path, true, [&](const std::filesystem::path& temporary) {
      write_picture(temporary, path, canvas.picture(), {.format = "png", .sample = image_library::SampleType::uint8});
    });
  } catch (const ImageWriteError& e) {
    throw UserError(e.what());
  }
}

}  // namespace nelf::app
