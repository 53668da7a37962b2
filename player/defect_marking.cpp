#include "player/defect_marking.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <utility>

#include "core/chart_style.hpp"
#include "core/image_library.hpp"
#include "core/user_error.hpp"
#include "player/calibrate_session.hpp"
#include "player/key_bindings.hpp"

namespace nelf {

namespace {

constexpr std::array<DefectField, 5> kFields = {DefectField::black, DefectField::white, DefectField::red,
                                                DefectField::green, DefectField::blue};

const char* eye_name(Eye eye) { return eye == Eye::left ? "left" : "right"; }

std::string defect_text(const PixelDefect& d) {
  if (d.kind == DefectKind::dead) return fmt::format("{} {} {} dead", eye_name(d.eye), d.x, d.y);
  return fmt::format("{} {} {} stuck {} {} {}", eye_name(d.eye), d.x, d.y, d.stuck_rgb[0], d.stuck_rgb[1],
                     d.stuck_rgb[2]);
}

std::string count_text(std::size_t n) { return fmt::format("{} defect{}", n, n == 1 ? "" : "s"); }

Rgba to_rgba(std::array<std::uint8_t, 3> rgb) { return Rgba{rgb[0] / 255.f, rgb[1] / 255.f, rgb[2] / 255.f, 1.f}; }

// Sets the pixel when it is on the panel.
void plot(Image& image, int x, int y, Rgba colour) {
  if (x >= 0 && y >= 0 && x < image.width() && y < image.height()) image.at(x, y) = colour;
}

// The text box as the on-screen messages draw it (compositor/overlays/text_overlay): white text on
// a black box of this opacity.
constexpr float kBoxOpacity = 0.6f;

// `text` in a box centred horizontally along the top edge of `image` (or the bottom one).
void draw_text_box(Image& image, const std::string& text, bool at_top) {
  const std::string font = chart::font();
  int font_px = std::max(10, image.height() / 32);
  auto extent = image_library::text_size(text, font_px, font);
  if (!extent)
    throw std::runtime_error(
        fmt::format("cannot render the on-screen text with font {} (install fonts-dejavu-core)", font));
  const int widest = image.width() * 95 / 100;
  if (extent->width() + 2 * (font_px / 3) > widest) {
    font_px = std::max(6, font_px * widest / (extent->width() + 2 * (font_px / 3)));
    extent = image_library::text_size(text, font_px, font);
    if (!extent) throw std::runtime_error(fmt::format("cannot render the on-screen text with font {}", font));
  }
  const int pad = std::max(2, font_px / 3);
  const int ascent = std::max(static_cast<int>(std::lround(0.95 * font_px)), -extent->y_begin);
  const int descent = std::max(static_cast<int>(std::lround(0.25 * font_px)), extent->y_end);
  const int width = std::min(image.width(), extent->width() + 2 * pad);
  const int height = std::min(image.height(), ascent + descent + 2 * pad);
  std::vector<float> label(static_cast<std::size_t>(width) * height * 4, 0.f);
  for (std::size_t i = 3; i < label.size(); i += 4) label[i] = kBoxOpacity;
  const float white[4] = {1.f, 1.f, 1.f, 1.f};
  try {
    image_library::render_text({.values = label.data(), .width = width, .height = height, .channels = 4},
                               pad - extent->x_begin, pad + ascent, text, font_px, font, white);
  } catch (const image_library::ImageLibraryError& e) {
    throw std::runtime_error(fmt::format("cannot render the on-screen text: {}", e.what()));
  }
  const int x0 = (image.width() - width) / 2, y0 = at_top ? 0 : image.height() - height;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float* l = &label[(static_cast<std::size_t>(y) * width + x) * 4];
      Rgba& p = image.at(x0 + x, y0 + y);
      const float a = std::clamp(l[3], 0.f, 1.f);
      p = Rgba{p.r * (1 - a) + l[0] * a, p.g * (1 - a) + l[1] * a, p.b * (1 - a) + l[2] * a, 1.f};
    }
}

}  // namespace

std::string defect_field_name(DefectField field) {
  switch (field) {
    case DefectField::black:
      return "black";
    case DefectField::white:
      return "white";
    case DefectField::red:
      return "red";
    case DefectField::green:
      return "green";
    case DefectField::blue:
      return "blue";
  }
  return "black";
}

std::optional<DefectField> parse_defect_field(std::string_view name) {
  for (DefectField f : kFields)
    if (defect_field_name(f) == name) return f;
  return std::nullopt;
}

std::vector<std::string> defect_field_names() {
  std::vector<std::string> names;
  for (DefectField f : kFields) names.push_back(defect_field_name(f));
  return names;
}

std::array<std::uint8_t, 3> defect_field_rgb(DefectField field) {
  switch (field) {
    case DefectField::black:
      return {0, 0, 0};
    case DefectField::white:
      return {255, 255, 255};
    case DefectField::red:
      return {255, 0, 0};
    case DefectField::green:
      return {0, 255, 0};
    case DefectField::blue:
      return {0, 0, 255};
  }
  return {0, 0, 0};
}

std::array<std::uint8_t, 3> DefectMarking::contrast_rgb(DefectField field) {
  const auto rgb = defect_field_rgb(field);
  return {static_cast<std::uint8_t>(255 - rgb[0]), static_cast<std::uint8_t>(255 - rgb[1]),
          static_cast<std::uint8_t>(255 - rgb[2])};
}

DefectMarking::DefectMarking(std::array<int, 2> panel, DefectMap map, DefectField field)
    : panel_(panel), map_(std::move(map)), field_(field) {
  if (panel_[0] <= 0 || panel_[1] <= 0)
    throw std::invalid_argument(fmt::format("an empty {}x{} panel", panel_[0], panel_[1]));
  for (auto& c : cursors_) c = {panel_[0] / 2, panel_[1] / 2};
}

const std::vector<std::string>& DefectMarking::help_lines() {
  static const std::vector<std::string> lines = key_help(KeyScope::defects);
  return lines;
}

const PixelDefect* DefectMarking::defect_at_cursor() const {
  const auto [x, y] = cursor();
  for (const PixelDefect& d : map_.defects)
    if (d.eye == eye_ && d.x == x && d.y == y) return &d;
  return nullptr;
}

std::string DefectMarking::status_line() const {
  const auto [x, y] = cursor();
  std::string line = fmt::format("{} {} {} | field {} | {}", eye_name(eye_), x, y, defect_field_name(field_),
                                 count_text(map_.defects.size()));
  if (const PixelDefect* d = defect_at_cursor())
    line += d->kind == DefectKind::dead
                ? " | marked dead"
                : fmt::format(" | marked stuck {} {} {}", d->stuck_rgb[0], d->stuck_rgb[1], d->stuck_rgb[2]);
  return line;
}

DefectStep DefectMarking::move(int dx, int dy) {
  auto& c = cursors_[static_cast<int>(eye_)];
  const std::array<int, 2> next = {std::clamp(c[0] + dx, 0, panel_[0] - 1), std::clamp(c[1] + dy, 0, panel_[1] - 1)};
  DefectStep step;
  step.changed = next != c;
  if (!step.changed) step.message = "edge of the panel";
  c = next;
  return step;
}

DefectStep DefectMarking::set_field(DefectField field) {
  DefectStep step;
  step.changed = field != field_;
  field_ = field;
  return step;
}

DefectStep DefectMarking::mark(DefectKind kind) {
  DefectStep step;
  PixelDefect d;
  d.eye = eye_;
  d.x = cursor()[0];
  d.y = cursor()[1];
  d.kind = kind;
  if (kind == DefectKind::stuck) {
    if (field_ == DefectField::black) {
      step.message =
          "not marked: a pixel stuck at black is dead (d); for stuck, show the field it disappears into, then s";
      return step;
    }
    d.stuck_rgb = defect_field_rgb(field_);
  }
  const auto same_pixel = [&](const PixelDefect& other) {
    return other.eye == d.eye && other.x == d.x && other.y == d.y;
  };
  const auto found = std::find_if(map_.defects.begin(), map_.defects.end(), same_pixel);
  if (found != map_.defects.end() && *found == d) {
    step.message = fmt::format("already marked: {}", defect_text(d));
    return step;
  }
  if (found != map_.defects.end())
    *found = d;  // the pixel keeps its place in the file
  else
    map_.defects.push_back(d);
  step.changed = step.marked = true;
  step.message = fmt::format("marked {} ({})", defect_text(d), count_text(map_.defects.size()));
  return step;
}

DefectStep DefectMarking::unmark() {
  DefectStep step;
  const PixelDefect* d = defect_at_cursor();
  if (!d) {
    step.message = fmt::format("{} {} {} is not marked", eye_name(eye_), cursor()[0], cursor()[1]);
    return step;
  }
  const std::string text = defect_text(*d);
  map_.defects.erase(map_.defects.begin() + (d - map_.defects.data()));
  step.changed = step.marked = true;
  step.message = fmt::format("unmarked {} ({})", text, count_text(map_.defects.size()));
  return step;
}

DefectStep DefectMarking::next_defect() {
  DefectStep step;
  if (map_.defects.empty()) {
    step.message = "no pixel is marked";
    return step;
  }
  const PixelDefect* here = defect_at_cursor();
  const std::size_t next = here ? (static_cast<std::size_t>(here - map_.defects.data()) + 1) % map_.defects.size() : 0;
  const PixelDefect& d = map_.defects[next];
  eye_ = d.eye;
  cursors_[static_cast<int>(d.eye)] = {d.x, d.y};
  step.changed = true;
  step.message = fmt::format("defect {} of {}: {}", next + 1, map_.defects.size(), defect_text(d));
  return step;
}

DefectStep DefectMarking::apply(const KeyPress& key) {
  DefectStep step;
  if (key.named == KeyPress::Named::none && (key.ctrl || key.alt)) {
    // Ctrl+C in the window quits as it would in the terminal; other combinations are not ours.
    step.quit = key.ctrl && (key.character == U'c' || key.character == U'q');
    return step;
  }
  const std::optional<Command> command = command_for(KeyScope::defects, key);
  if (!command) {
    if (key.named == KeyPress::Named::none && key.character >= 0x20 && key.character < 0x7f)
      step.message = fmt::format("key '{}' does nothing (h: help)", static_cast<char>(key.character));
    return step;
  }
  const int px = key.ctrl ? coarser_step_px : key.shift ? coarse_step_px : fine_step_px;
  switch (*command) {
    case Command::next_eye:
      eye_ = eye_ == Eye::left ? Eye::right : Eye::left;
      step.changed = true;
      return step;
    case Command::cursor_left:
      return move(-px, 0);
    case Command::cursor_right:
      return move(px, 0);
    case Command::cursor_up:
      return move(0, -px);
    case Command::cursor_down:
      return move(0, px);
    case Command::field_next: {
      const auto at = static_cast<std::size_t>(std::find(kFields.begin(), kFields.end(), field_) - kFields.begin());
      return set_field(kFields[(at + (key.shift ? kFields.size() - 1 : 1)) % kFields.size()]);
    }
    case Command::field_black:
      return set_field(DefectField::black);
    case Command::field_white:
      return set_field(DefectField::white);
    case Command::field_red:
      return set_field(DefectField::red);
    case Command::field_green:
      return set_field(DefectField::green);
    case Command::field_blue:
      return set_field(DefectField::blue);
    case Command::mark_dead:
      return mark(DefectKind::dead);
    case Command::mark_stuck:
      return mark(DefectKind::stuck);
    case Command::unmark:
      return unmark();
    case Command::next_defect:
      return next_defect();
    case Command::status_line:
      status_shown_ = !status_shown_;
      step.changed = true;
      return step;
    case Command::save:
      step.save = true;
      return step;
    case Command::help:
      step.help = true;
      return step;
    case Command::quit:
      step.quit = true;
      return step;
    default:
      return step;  // another scope's command: not bound here
  }
}

namespace {

// The ring of `d`'s marker.
void draw_marker(Image& image, const PixelDefect& d, Rgba colour) {
  const int r = DefectMarking::marker_radius_px;
  for (int i = -r; i <= r; ++i)
    for (const auto& [x, y] : {std::pair{d.x + i, d.y - r}, std::pair{d.x + i, d.y + r}, std::pair{d.x - r, d.y + i},
                               std::pair{d.x + r, d.y + i}}) {
      // Stuck: every other pixel of the ring (the corners included), so that the kinds differ.
      if (d.kind == DefectKind::stuck && (x - d.x + y - d.y) % 2 != 0) continue;
      plot(image, x, y, colour);
    }
}

}  // namespace

Image DefectMarking::field_image(std::array<int, 2> panel, DefectField field, const DefectMap& map, Eye eye) {
  Image image(panel[0], panel[1]);
  std::fill(image.pixels().begin(), image.pixels().end(), to_rgba(defect_field_rgb(field)));
  const Rgba contrast = to_rgba(contrast_rgb(field));
  for (const PixelDefect& d : map.defects)
    if (d.eye == eye) draw_marker(image, d, contrast);
  return image;
}

Image DefectMarking::panel_image(Eye eye, const std::string& text) const {
  Image image = field_image(panel_, field_, map_, eye);
  if (eye != eye_) return image;
  const Rgba contrast = to_rgba(contrast_rgb(field_));
  const auto [cx, cy] = cursor(eye);
  if (status_shown_ && !text.empty()) {
    draw_text_box(image, text, cy >= panel_[1] / 2);
    // Over the box the markers stay visible.
    for (const PixelDefect& d : map_.defects)
      if (d.eye == eye) draw_marker(image, d, contrast);
  }
  for (int i = cursor_gap_px; i < cursor_gap_px + cursor_arm_px; ++i) {
    plot(image, cx - i, cy, contrast);
    plot(image, cx + i, cy, contrast);
    plot(image, cx, cy - i, contrast);
    plot(image, cx, cy + i, contrast);
  }
  return image;
}

DefectMapSave defect_map_save(const Profile& profile, const std::string& save) {
  DefectMapSave where;
  where.profile = save;
  if (!profile.correction.defect_map_path.empty()) {
    where.map = profile.correction.defect_map_path;
  } else if (!save.empty()) {
    const std::filesystem::path p(save);
    where.map = p.parent_path() / (p.stem().string() + ".defects");
  }
  return where;
}

std::string save_defect_map(const Profile& profile, const DefectMap& map, const DefectMapSave& where) {
  if (where.map.empty()) throw std::logic_error("save_defect_map: nowhere to save");
  try {
    write_defect_map(where.map, map);
  } catch (const DefectMapError& e) {
    throw UserError(e.what(), 1);
  }
  std::string line = fmt::format("saved {} to {}", count_text(map.defects.size()), where.map.string());
  if (!where.profile.empty()) {
    // The saved profile names the map relative to its own directory (save_calibrated_profile).
    Profile saved = profile;
    std::error_code ec;
    saved.correction.defect_map_path = std::filesystem::absolute(where.map, ec);
    if (ec) saved.correction.defect_map_path = where.map;
    saved.correction.defect_map = where.map.filename().string();
    saved.correction.defects = std::make_shared<const DefectMap>(map);
    save_calibrated_profile(saved, where.profile);
    line += fmt::format(" and {} naming it", where.profile);
  }
  return line;
}

}  // namespace nelf
