#include "app/heatmap.hpp"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <system_error>

#include "app/commands.hpp"
#include "compositor/chart_style.hpp"
#include "hmz_output/image_sink.hpp"

namespace nelf::app {

namespace {

using Colour = chart::Rgb;

using chart::viridis;

class Canvas {
 public:
  Canvas(int width, int height)
      : buffer_(OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::FLOAT)), font_(chart::font()) {
    OIIO::ImageBufAlgo::fill(buffer_, {1.f, 1.f, 1.f});
  }
  void rectangle(int x0, int y0, int x1, int y1, const Colour& c) {
    OIIO::ImageBufAlgo::fill(buffer_, {c[0], c[1], c[2]}, OIIO::ROI(x0, x1, y0, y1, 0, 1, 0, 3));
  }
  void text(int x, int y, const std::string& s, int size, OIIO::ImageBufAlgo::TextAlignX align_x,
            OIIO::ImageBufAlgo::TextAlignY align_y = OIIO::ImageBufAlgo::TextAlignY::Center,
            const Colour& c = {0.f, 0.f, 0.f}) {
    const float colour[3] = {c[0], c[1], c[2]};
    if (!OIIO::ImageBufAlgo::render_text(buffer_, x, y, s, size, font_, colour, align_x, align_y))
      throw UserError(
          fmt::format("cannot draw the heatmap labels ({}): install a TrueType font, e.g. Debian's "
                      "fonts-dejavu-core",
                      buffer_.geterror()));
  }
  OIIO::ImageBuf& buffer() { return buffer_; }

 private:
  OIIO::ImageBuf buffer_;
  std::string font_;
};

}  // namespace

void write_heatmap_png(const Heatmap& map, const std::filesystem::path& path) {
  using AlignX = OIIO::ImageBufAlgo::TextAlignX;
  using AlignY = OIIO::ImageBufAlgo::TextAlignY;
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

  constexpr int cell_w = 46, cell_h = 34, left = 130, top = 60, bottom = 80, bar_gap = 30, bar_w = 24, right = 90;
  const int plot_w = columns * cell_w, plot_h = rows * cell_h;
  Canvas canvas(left + plot_w + bar_gap + bar_w + right, top + plot_h + bottom);

  canvas.text(left + plot_w / 2, top / 2, map.title, 20, AlignX::Center);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      const double v = map.values[r][c];
      const int x0 = left + c * cell_w, y0 = top + r * cell_h;
      const Colour colour = std::isfinite(v) ? viridis((v - lo) / (hi - lo)) : Colour{0.7f, 0.7f, 0.7f};
      canvas.rectangle(x0, y0, x0 + cell_w, y0 + cell_h, colour);
      // Dark text on the light (yellow-green) end of the map, white on the dark end.
      const double luminance = 0.2126 * colour[0] + 0.7152 * colour[1] + 0.0722 * colour[2];
      const Colour ink = luminance > 0.45 ? Colour{0.f, 0.f, 0.f} : Colour{1.f, 1.f, 1.f};
      canvas.text(x0 + cell_w / 2, y0 + cell_h / 2, std::isfinite(v) ? fmt::format("{:.0f}", v) : "-", 14,
                  AlignX::Center, AlignY::Center, ink);
    }
    canvas.text(left - 8, top + r * cell_h + cell_h / 2, map.y_ticks[r], 14, AlignX::Right);
  }
  for (int c = 0; c < columns; ++c)
    canvas.text(left + c * cell_w + cell_w / 2, top + plot_h + 14, map.x_ticks[c], 13, AlignX::Center);
  canvas.text(left + plot_w / 2, top + plot_h + 50, map.x_label, 16, AlignX::Center);
  canvas.text(10, top - 14, map.y_label, 16, AlignX::Left);

  // Colour bar: top = highest value.
  const int bar_x = left + plot_w + bar_gap;
  for (int y = 0; y < plot_h; ++y)
    canvas.rectangle(bar_x, top + y, bar_x + bar_w, top + y + 1, viridis(1.0 - (y + 0.5) / plot_h));
  constexpr int bar_ticks = 5;
  for (int k = 0; k < bar_ticks; ++k) {
    const double f = static_cast<double>(k) / (bar_ticks - 1);
    const int y = top + static_cast<int>(std::lround((1.0 - f) * (plot_h - 1)));
    canvas.rectangle(bar_x + bar_w, y, bar_x + bar_w + 5, y + 1, {0.f, 0.f, 0.f});
    canvas.text(bar_x + bar_w + 8, y, fmt::format("{:.1f}", lo + f * (hi - lo)), 13, AlignX::Left);
  }
  canvas.text(bar_x + bar_w / 2, top - 14, map.value_label, 16, AlignX::Center);

  try {
    write_file_atomically(path, true, [&](const std::filesystem::path& temporary) {
      if (!canvas.buffer().write(temporary.string(), OIIO::TypeDesc::UINT8, "png"))
        throw UserError(fmt::format("cannot write '{}': {}", path.string(), canvas.buffer().geterror()));
    });
  } catch (const ImageWriteError& e) {
    throw UserError(e.what());
  }
}

}  // namespace nelf::app
