#pragma once
// The keys of `nelf calibrate --defects`, without any window: a flat field shown on both panels
// without the lens mapping, a one-pixel cursor per eye, and the defect map being made
// (optics/defect_map.hpp). apply() takes one key press and says what changed; panel_image() draws
// what an eye's panel shows for the current state.
//
// The stuck colour rule: a stuck pixel shows one colour whatever it is sent, so it disappears on
// the field of that colour. `s` marks the pixel under the cursor stuck at the colour of the field
// shown: find the pixel on the black field (where it is bright), then cycle the field until it
// vanishes and press `s` (a pixel that vanishes on the white field is `stuck 255 255 255`). On the
// black field `s` refuses: a pixel stuck at black is dead (`d`). Mixtures (a pixel stuck yellow
// vanishes on none of the five fields) are written into the map by hand.
//
// Which key does what is the defects rows of player/key_bindings.cpp.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/image.hpp"
#include "core/keys.hpp"
#include "optics/defect_map.hpp"
#include "optics/profile.hpp"

namespace nelf {

enum class DefectField { black, white, red, green, blue };
std::string defect_field_name(DefectField field);  // "black", "white", ...
std::optional<DefectField> parse_defect_field(std::string_view name);
std::vector<std::string> defect_field_names();  // in the order space cycles them
std::array<std::uint8_t, 3> defect_field_rgb(DefectField field);

struct DefectStep {
  bool changed = false;  // draw the panels again
  bool save = false;     // write the map now (w)
  bool quit = false;     // q / Esc
  bool help = false;     // show help_lines()
  std::string message;   // one line for the screen and the terminal (ASCII), empty for nothing to say
  bool marked = false;   // the map changed (the message says how)
};

class DefectMarking {
 public:
  // `panel`: the panel's width and height; `map`: the defects known so far (the profile's map),
  // each inside the panel. The cursor starts at the centre of each panel, on the left eye.
  DefectMarking(std::array<int, 2> panel, DefectMap map, DefectField field = DefectField::black);

  DefectStep apply(const KeyPress& key);

  Eye eye() const { return eye_; }
  std::array<int, 2> cursor(Eye eye) const { return cursors_[static_cast<int>(eye)]; }
  std::array<int, 2> cursor() const { return cursor(eye_); }
  DefectField field() const { return field_; }
  const DefectMap& map() const { return map_; }
  std::array<int, 2> panel() const { return panel_; }
  bool status_shown() const { return status_shown_; }

  // "left 640 360 | field black | 3 defects", and what the pixel under the cursor is marked as.
  std::string status_line() const;

  // What `eye`'s panel shows: the flat field; the markers of its defects (a 5x5 square ring around
  // each, whole for dead, dotted for stuck: the pixel and its eight neighbours stay as they are);
  // on the selected eye, the cursor (a crosshair in the field's contrasting colour whose arms
  // start cursor_gap_px from the pixel) and, when status_shown(), `text` as the on-screen messages
  // look (white on a translucent dark box) along the top or bottom edge, whichever is farther from
  // the cursor. Throws std::runtime_error when the text cannot be rendered (no font).
  Image panel_image(Eye eye, const std::string& text) const;
  // The flat field `field` with the markers of `map`'s defects of `eye`: panel_image() without the
  // cursor and the text (what the headless image shows).
  static Image field_image(std::array<int, 2> panel, DefectField field, const DefectMap& map, Eye eye);

  // The colour the cursor and the markers are drawn in on `field`: its complement (white on black,
  // black on white, cyan on red, ...).
  static std::array<std::uint8_t, 3> contrast_rgb(DefectField field);

  static const std::vector<std::string>& help_lines();

  static constexpr int fine_step_px = 1, coarse_step_px = 10, coarser_step_px = 100;  // arrows, Shift, Ctrl
  static constexpr int cursor_gap_px = 4, cursor_arm_px = 10;
  static constexpr int marker_radius_px = 2;

 private:
  DefectStep move(int dx, int dy);
  DefectStep set_field(DefectField field);
  DefectStep mark(DefectKind kind);
  DefectStep unmark();
  DefectStep next_defect();
  // The defect at the cursor of the selected eye, or nullptr.
  const PixelDefect* defect_at_cursor() const;

  std::array<int, 2> panel_;
  DefectMap map_;
  DefectField field_;
  Eye eye_ = Eye::left;
  std::array<std::array<int, 2>, 2> cursors_;
  bool status_shown_ = true;
};

// Where `nelf calibrate --defects` writes what it marked: the map to the file the profile names
// (correction.defect_map), or, when it names none, to `<stem>.defects` beside the --save profile
// (`my-hmz.defects` for my-hmz.toml), and the profile to --save naming the map. Without either,
// nowhere (map empty).
struct DefectMapSave {
  std::filesystem::path map;  // "" = nothing is written
  std::string profile;        // the --save profile ("" = none written)
};
DefectMapSave defect_map_save(const Profile& profile, const std::string& save);

// Writes `map` to `where.map`, then (where.profile given) `profile` to where.profile naming the map
// (relative to the saved profile's directory), so that the saved profile loads with the new map.
// Returns the line to show ("saved 3 defects to my-hmz.defects (my-hmz.toml names it)"). UserError
// (status 1) when a file cannot be written.
std::string save_defect_map(const Profile& profile, const DefectMap& map, const DefectMapSave& where);

}  // namespace nelf
