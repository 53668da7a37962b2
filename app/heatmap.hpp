#pragma once
// A labelled heatmap PNG (cells with their values, axes, colour bar), for `nelf simulate --sweep`.
#include <filesystem>
#include <string>
#include <vector>

#include "core/chart_style.hpp"

namespace nelf::app {

// A line drawn over the cells, row by row: in each row a vertical stroke at a position along the
// columns, joined to the next row's (a staircase, since each row is one value of its own).
struct HeatmapLine {
  std::vector<double> column_position;  // per row: 0 = the first column's centre, 1 the second's, ...
  chart::Rgb colour{0.9f, 0.1f, 0.1f};
};

struct Heatmap {
  std::string title;
  std::string x_label, y_label, value_label;
  std::vector<std::string> x_ticks;         // one per column, left to right
  std::vector<std::string> y_ticks;         // one per row, top to bottom
  std::vector<std::vector<double>> values;  // values[row][column]; non-finite cells are drawn grey
  std::vector<HeatmapLine> lines;           // over the cells, clamped to the plot
  std::string note;                         // one line under the x label (what the lines are)
  int value_decimals = 0;                   // in the cells
};

// Renders `map` and writes it as a PNG to `path` (through a temporary name, renamed at the end).
// Throws UserError when no font is available or the file cannot be written.
void write_heatmap_png(const Heatmap& map, const std::filesystem::path& path);

}  // namespace nelf::app
