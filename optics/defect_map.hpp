#pragma once
// A panel's dead and stuck pixels (correction.defect_map, docs/defects.md): a text file, one defect
// a line, read and validated against the panel it belongs to, and written back by `nelf calibrate`.
//
//   # comment (to the end of the line); blank lines are ignored
//   left 640 360 dead                  eye, column, row (0-based, row 0 the top), kind
//   right 12 700 stuck 255 255 255     stuck at an RGB value, 0..255 per channel
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "optics/profile.hpp"

namespace nelf {

enum class DefectKind { dead, stuck };

struct PixelDefect {
  Eye eye{};
  int x = 0, y = 0;  // column, row of the panel (row 0 the top)
  DefectKind kind = DefectKind::dead;
  std::array<std::uint8_t, 3> stuck_rgb{0, 0, 0};  // what a stuck pixel shows (dead: black)
  // What the pixel shows whatever it is sent: black for a dead pixel.
  std::array<std::uint8_t, 3> shown_rgb() const {
    return kind == DefectKind::dead ? std::array<std::uint8_t, 3>{0, 0, 0} : stuck_rgb;
  }
  friend bool operator==(const PixelDefect&, const PixelDefect&) = default;
};

struct DefectMap {
  std::vector<PixelDefect> defects;  // in the file's order
  bool empty() const { return defects.empty(); }
  friend bool operator==(const DefectMap&, const DefectMap&) = default;
};

// A problem with a defect map: one line naming the file, the line and the rule. A ProfileError, as
// the map is part of the profile (exit status 2).
class DefectMapError : public ProfileError {
 public:
  using ProfileError::ProfileError;
};

// Parses `text` for a panel of `panel` pixels (width, height); `origin` names it in messages.
// Throws DefectMapError for a malformed line, a pixel outside the panel or a pixel given twice.
DefectMap parse_defect_map(std::string_view text, const std::string& origin, std::array<int, 2> panel);

// Reads the file at `path` (DefectMapError when it is missing or unreadable).
DefectMap read_defect_map(const std::filesystem::path& path, std::array<int, 2> panel);

// The map as the text parse_defect_map reads back equal (a header comment, then one line a defect).
std::string defect_map_text(const DefectMap& map);

// Writes the map to `path` through a temporary file renamed over it, so that a failure leaves the
// old file (or none) rather than half a map. Throws DefectMapError naming the path when it cannot.
void write_defect_map(const std::filesystem::path& path, const DefectMap& map);

}  // namespace nelf
