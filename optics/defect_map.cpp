#include "optics/defect_map.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <charconv>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>
#include <utility>

namespace nelf {

namespace {

// The whitespace-separated words of a line, the comment cut off.
std::vector<std::string_view> words_of(std::string_view line) {
  if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

bool parse_int(std::string_view word, long long& value) {
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  return ec == std::errc() && end == word.data() + word.size();
}

// The word as a message shows it: printable ASCII only, cut short.
std::string shown(std::string_view word) {
  std::string out;
  for (char c : word.substr(0, 40)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  if (word.size() > 40) out += "...";
  return out;
}

const char* eye_name(Eye eye) { return eye == Eye::left ? "left" : "right"; }

}  // namespace

DefectMap parse_defect_map(std::string_view text, const std::string& origin, std::array<int, 2> panel) {
  DefectMap map;
  std::set<std::tuple<int, int, int>> seen;
  std::vector<int> first_line;  // per defect, for the duplicate message
  int line_number = 0;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t newline = text.find('\n', pos);
    const std::string_view line =
        text.substr(pos, newline == std::string_view::npos ? std::string_view::npos : newline - pos);
    pos = newline == std::string_view::npos ? text.size() + 1 : newline + 1;
    ++line_number;
    const auto words = words_of(line);
    if (words.empty()) continue;
    const auto fail = [&](const std::string& rule) {
      throw DefectMapError(fmt::format("{}:{}: {}", origin, line_number, rule));
    };
    constexpr const char* form = "'EYE X Y dead' or 'EYE X Y stuck R G B'";
    PixelDefect d;
    if (words[0] == "left")
      d.eye = Eye::left;
    else if (words[0] == "right")
      d.eye = Eye::right;
    else
      fail(fmt::format("the eye must be left or right, got '{}' (a defect is {})", shown(words[0]), form));
    if (words.size() < 4) fail(fmt::format("a defect is {}, got {} word(s)", form, words.size()));
    long long x = 0, y = 0;
    if (!parse_int(words[1], x) || !parse_int(words[2], y))
      fail(fmt::format("the column and row must be whole numbers, got '{}' '{}'", shown(words[1]), shown(words[2])));
    if (x < 0 || y < 0 || x >= panel[0] || y >= panel[1])
      fail(fmt::format("pixel ({}, {}) is outside the {}x{} panel (columns 0..{}, rows 0..{})", x, y, panel[0],
                       panel[1], panel[0] - 1, panel[1] - 1));
    d.x = static_cast<int>(x);
    d.y = static_cast<int>(y);
    if (words[3] == "dead") {
      if (words.size() != 4) fail(fmt::format("'dead' takes no values, got '{}' after it", shown(words[4])));
      d.kind = DefectKind::dead;
    } else if (words[3] == "stuck") {
      if (words.size() != 7) fail(fmt::format("'stuck' takes three values R G B (0..255), got {}", words.size() - 4));
      d.kind = DefectKind::stuck;
      for (std::size_t c = 0; c < 3; ++c) {
        long long v = 0;
        if (!parse_int(words[4 + c], v) || v < 0 || v > 255)
          fail(fmt::format("a stuck value must be a whole number 0..255, got '{}'", shown(words[4 + c])));
        d.stuck_rgb[c] = static_cast<std::uint8_t>(v);
      }
    } else {
      fail(fmt::format("the kind must be dead or stuck, got '{}' (a defect is {})", shown(words[3]), form));
    }
    if (!seen.insert({static_cast<int>(d.eye), d.x, d.y}).second) {
      int first = 0;
      for (std::size_t k = 0; k < map.defects.size(); ++k)
        if (map.defects[k].eye == d.eye && map.defects[k].x == d.x && map.defects[k].y == d.y) first = first_line[k];
      fail(fmt::format("{} pixel ({}, {}) is already given on line {}: one line per pixel", eye_name(d.eye), d.x, d.y,
                       first));
    }
    map.defects.push_back(d);
    first_line.push_back(line_number);
  }
  return map;
}

DefectMap read_defect_map(const std::filesystem::path& path, std::array<int, 2> panel) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw DefectMapError(fmt::format("{}: cannot read the defect map: {}", path.string(),
                                     std::filesystem::exists(path, ec) ? "not a regular file" : "no such file"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DefectMapError(fmt::format("{}: cannot read the defect map: permission denied", path.string()));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw DefectMapError(fmt::format("{}: cannot read the defect map: read error", path.string()));
  return parse_defect_map(text.str(), path.string(), panel);
}

std::string defect_map_text(const DefectMap& map) {
  std::string out =
      "# nelf defect map: EYE COLUMN ROW dead | EYE COLUMN ROW stuck R G B (row 0 the top; docs/defects.md)\n";
  for (const PixelDefect& d : map.defects) {
    if (d.kind == DefectKind::dead)
      out += fmt::format("{} {} {} dead\n", eye_name(d.eye), d.x, d.y);
    else
      out += fmt::format("{} {} {} stuck {} {} {}\n", eye_name(d.eye), d.x, d.y, d.stuck_rgb[0], d.stuck_rgb[1],
                         d.stuck_rgb[2]);
  }
  return out;
}

void write_defect_map(const std::filesystem::path& path, const DefectMap& map) {
  const std::string text = defect_map_text(map);
  std::filesystem::path temporary = path;
  temporary += fmt::format(".tmp-{}", ::getpid());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out)
      throw DefectMapError(fmt::format("{}: cannot write the defect map: cannot create a file there", path.string()));
    out << text;
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      throw DefectMapError(fmt::format("{}: cannot write the defect map: write error (disk full?)", path.string()));
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw DefectMapError(fmt::format("{}: cannot write the defect map: {}", path.string(), ec.message()));
  }
}

}  // namespace nelf
