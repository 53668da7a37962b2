#pragma once
// A labelled heatmap PNG (cells with their values, axes, colour bar), for `nelf simulate --sweep`.
#include <filesystem>
#include <string>
#include <vector>

namespace nelf::app {

struct Heatmap {
  std::string title;
  std::string x_label, y_label, value_label;
  std::vector<std::string> x_ticks;         // one per column, left to right
  std::vector<std::string> y_ticks;         // one per row, top to bottom
  std::vector<std::vector<double>> values;  // values[row][column]; non-finite cells are drawn grey
};

// Renders `map` and writes it as a PNG to `path` (through a temporary name, renamed at the end).
// Throws UserError when no font is available or the file cannot be written.
void write_heatmap_png(const Heatmap& map, const std::filesystem::path& path);

}  // namespace nelf::app
