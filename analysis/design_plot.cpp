#include "analysis/design_plot.hpp"

#include "core/chart_style.hpp"
#include "hmz_output/image_sink.hpp"

#include <fmt/format.h>
#include <unistd.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/image_library.hpp"
#include "optics/optics.hpp"

namespace nelf {

int trade_space_resolution_px(const Profile& profile, double focal_mm, double lens_pitch_mm) {
  optics::AxisGeometry g;
  g.display_mm = profile.display.width_mm();
  g.pixel_pitch_mm = profile.display.pixel_pitch_mm.x;
  g.lens_pitch_mm = lens_pitch_mm;
  g.focal_mm = focal_mm;
  g.eye_relief_mm = profile.viewing.eye_relief_mm;
  g.image_mm = profile.viewing.virtual_image_mm;
  return optics::resolution_px(g);
}

namespace {

using chart::Rgb;

constexpr Rgb kWhite = {1.f, 1.f, 1.f};
constexpr Rgb kBlack = {0.f, 0.f, 0.f};
constexpr Rgb kDarkGrey = {0.25f, 0.25f, 0.25f};

using chart::viridis;

// A "nice" step (1, 2 or 5 × 10^k) giving roughly `count` intervals over `range`.
double nice_step(double range, int count) {
  const double raw = range / count;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double fraction = raw / magnitude;
  const double nice = fraction <= 1.0 ? 1.0 : fraction <= 2.0 ? 2.0 : fraction <= 5.0 ? 5.0 : 10.0;
  return nice * magnitude;
}

std::string tick_label(double value, double step) {
  // As many decimals as the step needs, no more: 0.5 → "0.5", 1 → "1", 0.25 → "0.25".
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  return fmt::format("{:.{}f}", value, std::max(decimals, 0));
}

// An RGB raster in floating point; the picture is drawn here, the text by OpenImageIO onto it.
class Canvas {
 public:
  Canvas(int width, int height) : width_(width), height_(height), pixels_(std::size_t(width) * height * 3, 1.f) {}
  int width() const { return width_; }
  int height() const { return height_; }
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }
  void set(int x, int y, Rgb c) {
    if (inside(x, y)) std::copy(c.begin(), c.end(), pixels_.begin() + std::ptrdiff_t(offset(x, y)));
  }
  // Mixes `c` over the pixel with opacity `alpha`.
  void blend(int x, int y, Rgb c, float alpha) {
    if (!inside(x, y)) return;
    float* p = &pixels_[offset(x, y)];
    for (std::size_t k = 0; k < 3; ++k) p[k] = p[k] * (1.f - alpha) + c[k] * alpha;
  }
  void fill_rect(int x0, int y0, int x1, int y1, Rgb c) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) set(x, y, c);
  }
  // A line `thickness` pixels wide (square brush), sampled densely enough to leave no gaps.
  void line(double x0, double y0, double x1, double y1, Rgb c, int thickness = 1) {
    const int steps = static_cast<int>(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0)))) + 1;
    const int lo = -(thickness - 1) / 2, hi = thickness / 2;
    for (int s = 0; s <= steps; ++s) {
      const double t = static_cast<double>(s) / steps;
      const int x = static_cast<int>(std::lround(x0 + (x1 - x0) * t));
      const int y = static_cast<int>(std::lround(y0 + (y1 - y0) * t));
      for (int dy = lo; dy <= hi; ++dy)
        for (int dx = lo; dx <= hi; ++dx) set(x + dx, y + dy, c);
    }
  }
  void rect_outline(int x0, int y0, int x1, int y1, Rgb c, int thickness) {
    line(x0, y0, x1, y0, c, thickness);
    line(x1, y0, x1, y1, c, thickness);
    line(x1, y1, x0, y1, c, thickness);
    line(x0, y1, x0, y0, c, thickness);
  }
  void ring(double cx, double cy, double radius, Rgb c, double width) {
    for (int y = int(cy - radius - width); y <= int(cy + radius + width) + 1; ++y)
      for (int x = int(cx - radius - width); x <= int(cx + radius + width) + 1; ++x)
        if (std::abs(std::hypot(x - cx, y - cy) - radius) <= width / 2) set(x, y, c);
  }
  Rgb get(int x, int y) const {
    const float* p = &pixels_[offset(x, y)];
    return {p[0], p[1], p[2]};
  }
  image_library::Canvas raster() {
    return {.values = pixels_.data(), .width = width_, .height = height_, .channels = 3};
  }
  image_library::Picture picture() const {
    return {.values = pixels_.data(), .width = width_, .height = height_, .channels = 3, .pixel_stride = 3};
  }

 private:
  std::size_t offset(int x, int y) const { return (std::size_t(y) * std::size_t(width_) + std::size_t(x)) * 3; }
  int width_, height_;
  std::vector<float> pixels_;
};

// Text on the finished raster. Every call checks for failure: a missing font must be an error that
// says what to install, not a picture without labels.
class TextPainter {
 public:
  using AlignX = image_library::AlignX;
  using AlignY = image_library::AlignY;
  TextPainter(Canvas& canvas, std::string font) : canvas_(canvas), font_(std::move(font)) {}
  void draw(int x, int y, const std::string& text, int size, Rgb colour = kBlack, AlignX align_x = AlignX::left,
            AlignY align_y = AlignY::baseline, int shadow = 0) {
    try {
      image_library::render_text(canvas_.raster(), x, y, text, size, font_, colour, align_x, align_y, shadow);
    } catch (const image_library::ImageLibraryError& e) {
      fail(e.what());
    }
  }
  // Text running upwards (the y-axis label), centred on (cx, cy): drawn level on a label of its
  // own, then copied in turned a quarter anticlockwise.
  void draw_vertical(int cx, int cy, const std::string& text, int size) {
    const auto box = image_library::text_size(text, size, font_);
    if (!box) fail("cannot measure text");
    const int w = box->width() + 8, h = box->height() + 8;
    Canvas label(w, h);
    TextPainter(label, font_).draw(4 - box->x_begin, 4 - box->y_begin, text, size, kBlack);
    // The label's pixel (x, y) lands at (x0 + y, y0 + w - 1 - x).
    const int x0 = cx - h / 2, y0 = cy - w / 2;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) canvas_.set(x0 + y, y0 + w - 1 - x, label.get(x, y));
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw PlotError(fmt::format("cannot draw the plot's text with font '{}' (install fonts-dejavu-core): {}", font_,
                                why.empty() ? "unknown OpenImageIO error" : why));
  }
  Canvas& canvas_;
  std::string font_;
};

struct Axis {
  double lo, hi;
  int pixel_lo, pixel_hi;  // pixel of lo and of hi (hi may be the smaller pixel: the y axis grows up)
  double to_pixel(double v) const { return pixel_lo + (v - lo) / (hi - lo) * (pixel_hi - pixel_lo); }
  double from_pixel(double p) const { return lo + (p - pixel_lo) / (pixel_hi - pixel_lo) * (hi - lo); }
};

Canvas draw_plot(const Profile& profile) {
  constexpr int width = 1100, height = 820;
  constexpr int left = 110, right = 900, top = 96, bottom = 720;  // the plot area
  constexpr int bar_left = 940, bar_right = 970;                  // the colour bar

  // The ranges of Fig. 5, widened when this profile's lens array lies outside them.
  const bool mark = profile.lens_array.has_value();
  double f_hi = 10.0, w_hi = 5.0;
  if (mark) {
    f_hi = std::max(f_hi, std::ceil(profile.lens_array->focal_length_mm * 1.2));
    w_hi = std::max(w_hi, std::ceil(profile.lens_array->pitch_mm * 1.2));
  }
  const Axis fx{1.0, f_hi, left, right};
  const Axis wy{0.25, w_hi, bottom, top};

  // N_p at every pixel centre of the plot area.
  const int plot_w = right - left, plot_h = bottom - top;
  std::vector<int> resolution(std::size_t(plot_w) * plot_h);
  int max_resolution = 1;
  for (int y = 0; y < plot_h; ++y)
    for (int x = 0; x < plot_w; ++x) {
      const double f = fx.from_pixel(left + x + 0.5), w = wy.from_pixel(top + y + 0.5);
      const int n = trade_space_resolution_px(profile, f, w);
      resolution[std::size_t(y) * plot_w + x] = n;
      max_resolution = std::max(max_resolution, n);
    }
  const double bar_step = nice_step(max_resolution, 6);
  const double bar_max = std::ceil(max_resolution / bar_step) * bar_step;

  Canvas canvas(width, height);
  for (int y = 0; y < plot_h; ++y)
    for (int x = 0; x < plot_w; ++x) {
      const int n = resolution[std::size_t(y) * plot_w + x];
      canvas.set(left + x, top + y, viridis(n / bar_max));
    }

  // f/w_l < 1 (lenses faster than f/1, impractical to make as a microlens sheet): greyed and hatched.
  for (int y = top; y < bottom; ++y)
    for (int x = left; x < right; ++x) {
      const double f = fx.from_pixel(x + 0.5), w = wy.from_pixel(y + 0.5);
      if (f / w >= 1.0) continue;
      canvas.blend(x, y, {0.55f, 0.55f, 0.55f}, 0.55f);
      if ((x - y + 4096) % 14 < 2) canvas.blend(x, y, kDarkGrey, 0.7f);
    }
  // Its border, f = w_l.
  const double diagonal_end = std::min(fx.hi, wy.hi);
  canvas.line(fx.to_pixel(std::max(fx.lo, wy.lo)), wy.to_pixel(std::max(fx.lo, wy.lo)), fx.to_pixel(diagonal_end),
              wy.to_pixel(diagonal_end), kDarkGrey, 2);

  // Frame and ticks.
  canvas.rect_outline(left - 1, top - 1, right, bottom, kBlack, 2);
  const double f_step = nice_step(fx.hi - fx.lo, 9);
  const double w_step = nice_step(wy.hi - wy.lo, 9);
  std::vector<std::pair<int, std::string>> x_ticks, y_ticks;
  for (double f = std::ceil(fx.lo / f_step) * f_step; f <= fx.hi + 1e-9; f += f_step) {
    const int px = static_cast<int>(std::lround(fx.to_pixel(f)));
    canvas.line(px, bottom, px, bottom + 7, kBlack, 2);
    x_ticks.emplace_back(px, tick_label(f, f_step));
  }
  for (double w = std::ceil(wy.lo / w_step) * w_step; w <= wy.hi + 1e-9; w += w_step) {
    const int py = static_cast<int>(std::lround(wy.to_pixel(w)));
    canvas.line(left - 8, py, left - 1, py, kBlack, 2);
    y_ticks.emplace_back(py, tick_label(w, w_step));
  }

  // Colour bar, 0 at the bottom.
  for (int y = top; y < bottom; ++y) {
    const double value = (bottom - y - 0.5) / plot_h * bar_max;
    canvas.fill_rect(bar_left, y, bar_right, y + 1, viridis(value / bar_max));
  }
  canvas.rect_outline(bar_left - 1, top - 1, bar_right, bottom, kBlack, 1);
  std::vector<std::pair<int, std::string>> bar_ticks;
  for (double v = 0.0; v <= bar_max + 1e-9; v += bar_step) {
    const int py = static_cast<int>(std::lround(bottom - v / bar_max * plot_h));
    canvas.line(bar_right, py, bar_right + 6, py, kBlack, 2);
    bar_ticks.emplace_back(py, tick_label(v, bar_step));
  }

  // The profile's design: a white ring with a cross, outlined in black so it shows on any colour.
  double mark_x = 0, mark_y = 0;
  if (mark) {
    mark_x = fx.to_pixel(profile.lens_array->focal_length_mm);
    mark_y = wy.to_pixel(profile.lens_array->pitch_mm);
    canvas.ring(mark_x, mark_y, 10, kBlack, 5);
    canvas.ring(mark_x, mark_y, 10, kWhite, 2.5);
    canvas.line(mark_x - 16, mark_y, mark_x + 16, mark_y, kBlack, 4);
    canvas.line(mark_x, mark_y - 16, mark_x, mark_y + 16, kBlack, 4);
    canvas.line(mark_x - 15, mark_y, mark_x + 15, mark_y, kWhite, 2);
    canvas.line(mark_x, mark_y - 15, mark_x, mark_y + 15, kWhite, 2);
  }

  using TextAlignX = TextPainter::AlignX;
  using TextAlignY = TextPainter::AlignY;
  TextPainter text(canvas, chart::font());
  const std::string name = profile.name.empty() ? std::string("profile") : profile.name;
  text.draw(left, 40, fmt::format("Spatial resolution N_p (Eq. 8, horizontal) over the lens design space: {}", name),
            22);
  text.draw(left, 72,
            fmt::format("display {:.4g} mm ({} px at {:.4g} mm), eye relief d_e {:.4g} mm, virtual image d_o {:.6g} "
                        "mm, gap d_l from Eq. 1",
                        profile.display.width_mm(), profile.display.resolution[0], profile.display.pixel_pitch_mm.x,
                        profile.viewing.eye_relief_mm, profile.viewing.virtual_image_mm),
            15, {0.2f, 0.2f, 0.2f});
  for (const auto& [px, label] : x_ticks)
    text.draw(px, bottom + 12, label, 16, kBlack, TextAlignX::center, TextAlignY::top);
  for (const auto& [py, label] : y_ticks)
    text.draw(left - 13, py, label, 16, kBlack, TextAlignX::right, TextAlignY::center);
  for (const auto& [py, label] : bar_ticks)
    text.draw(bar_right + 10, py, label, 16, kBlack, TextAlignX::left, TextAlignY::center);
  text.draw((left + right) / 2, bottom + 58, "lens focal length f (mm)", 20, kBlack, TextAlignX::center,
            TextAlignY::baseline);
  text.draw_vertical(left - 72, (top + bottom) / 2, "lens pitch w_l (mm)", 20);
  text.draw_vertical(bar_right + 70, (top + bottom) / 2, "spatial resolution N_p (px)", 18);

  // Label the hatched region inside it, near the top-left corner where it is widest.
  text.draw(left + 14, top + 30, "f/w_l < 1: faster than f/1", 17, kWhite, TextAlignX::left, TextAlignY::baseline, 2);
  text.draw(left + 14, top + 52, "(impractical lenses)", 15, kWhite, TextAlignX::left, TextAlignY::baseline, 2);

  const int legend_y = height - 22;
  if (mark) {
    const int n = trade_space_resolution_px(profile, profile.lens_array->focal_length_mm, profile.lens_array->pitch_mm);
    const std::string label = fmt::format("{}: f {:.4g} mm, w_l {:.4g} mm, N_p {} px", name,
                                          profile.lens_array->focal_length_mm, profile.lens_array->pitch_mm, n);
    // Right of the mark unless that would leave the plot area.
    const auto box = image_library::text_size(label, 17, chart::font());
    const bool flip = mark_x + 22 + (box ? box->width() : 0) > right;
    text.draw(static_cast<int>(mark_x) + (flip ? -22 : 22), static_cast<int>(mark_y) - 14, label, 17, kWhite,
              flip ? TextAlignX::right : TextAlignX::left, TextAlignY::bottom, 2);
    text.draw(left, legend_y,
              "Marked: this profile's lens array. Hatched: f-number below 1. Bands: steps in the number of "
              "lenses used N_l (Eq. 6).",
              14, {0.2f, 0.2f, 0.2f});
  } else {
    text.draw(
        left, legend_y,
        fmt::format("{} has no lens array: nothing marked. Hatched: f-number below 1. Bands: steps in N_l (Eq. 6).",
                    name),
        14, {0.2f, 0.2f, 0.2f});
  }
  return canvas;
}

}  // namespace

void write_trade_space_plot(const Profile& profile, const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  const fs::path directory = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(directory, ec))
    throw PlotError(
        fmt::format("cannot write plot {}: directory {} does not exist", path.string(), directory.string()));
  if (fs::is_directory(path, ec))
    throw PlotError(fmt::format("cannot write plot {}: it is a directory", path.string()));

  // Ask for a writer before drawing, so that an unknown extension is reported by its own name.
  bool writable = false;
  try {
    writable = image_library::has_writer(path.string());
  } catch (const image_library::ImageLibraryError& e) {
    throw PlotError(fmt::format("cannot write plot {}: {}", path.string(), e.what()));
  }
  if (!writable) {
    throw PlotError(fmt::format("cannot write plot {}: no image format for extension '{}' (use .png)", path.string(),
                                path.extension().string()));
  }

  const Canvas image = draw_plot(profile);

  // The format comes from the final name: the temporary file has no extension.
  std::string format = path.extension().string().substr(1);
  std::transform(format.begin(), format.end(), format.begin(), [](unsigned char c) { return std::tolower(c); });
  try {
    write_file_atomically(path, true, [&](const fs::path& temporary) {
      write_picture(temporary, path, image.picture(), {.format = format, .sample = image_library::SampleType::uint8});
    });
  } catch (const ImageWriteError& e) {
    throw PlotError(fmt::format("plot: {}", e.what()));
  }
}

}  // namespace nelf
