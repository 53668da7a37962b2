#include "player/playlist.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "core/printable.hpp"
#include "core/user_error.hpp"
#include "inputs/still_source.hpp"

namespace nelf {
namespace {

namespace fs = std::filesystem;

std::string lowercase_extension(const std::string& name) {
  std::string ext = fs::path(name).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool is_m3u_name(const std::string& name) {
  const std::string ext = lowercase_extension(name);
  return ext == ".m3u" || ext == ".m3u8";
}

// A name FFmpeg opens by protocol, not a path (a URL, `synthetic:`, `x11:`): kept as it is.
bool is_url(const std::string& name) { return name.find("://") != std::string::npos; }

std::vector<std::string> directory_entries(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code type_ec;
    if (!it->is_regular_file(type_ec) || !is_media_file_name(it->path().filename().string())) continue;
    names.push_back(it->path().filename().string());
  }
  if (ec) throw UserError(fmt::format("{}: cannot list the folder ({})", printable(dir.string()), ec.message()), 2);
  if (names.empty())
    throw UserError(fmt::format("{}: the folder holds no image or video nelf plays", printable(dir.string())), 2);
  std::sort(names.begin(), names.end(), natural_less);
  std::vector<std::string> paths;
  for (const std::string& name : names) paths.push_back((dir / name).string());
  return paths;
}

std::vector<std::string> m3u_entries(const fs::path& playlist, const std::function<void(const std::string&)>& warn) {
  std::ifstream in(playlist);
  if (!in) throw UserError(fmt::format("{}: cannot read the playlist", printable(playlist.string())), 2);
  std::vector<std::string> entries;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    // An HLS playlist (#EXT-X- tags) is one stream in segments: FFmpeg plays it as one input.
    if (line.rfind("#EXT-X-", 0) == 0) return {playlist.string()};
    if (!line.empty() && line.back() == '\r') line.pop_back();                // written on Windows
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a UTF-8 byte order mark
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    std::string entry = line.substr(first);
    if (!is_url(entry) && fs::path(entry).is_relative()) entry = (playlist.parent_path() / entry).string();
    std::error_code ec;
    if (!is_url(entry) && !fs::exists(entry, ec)) {
      warn(
          fmt::format("{} line {}: {}: no such file, skipped", printable(playlist.string()), number, printable(entry)));
      continue;
    }
    entries.push_back(std::move(entry));
  }
  if (entries.empty())
    throw UserError(fmt::format("{}: the playlist has no entry to play", printable(playlist.string())), 2);
  return entries;
}

}  // namespace

bool is_media_file_name(const std::string& name) {
  static const std::vector<std::string> video = {".mkv", ".mk3d", ".mp4", ".m4v", ".mov",  ".avi", ".webm",
                                                 ".ts",  ".m2ts", ".mts", ".mpg", ".mpeg", ".wmv", ".flv",
                                                 ".ogv", ".3gp",  ".vob", ".y4m", ".nut"};
  return is_still_image_name(name) || std::find(video.begin(), video.end(), lowercase_extension(name)) != video.end();
}

bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  const auto digit = [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; };
  while (i < a.size() && j < b.size()) {
    if (digit(a[i]) && digit(b[j])) {
      std::size_t ei = i, ej = j;
      while (ei < a.size() && digit(a[ei])) ++ei;
      while (ej < b.size() && digit(b[ej])) ++ej;
      // As numbers: without leading zeros the longer run is larger, else the digits decide.
      std::size_t zi = i, zj = j;
      while (zi + 1 < ei && a[zi] == '0') ++zi;
      while (zj + 1 < ej && b[zj] == '0') ++zj;
      if (ei - zi != ej - zj) return ei - zi < ej - zj;
      if (const int c = a.compare(zi, ei - zi, b, zj, ej - zj); c != 0) return c < 0;
      if (ei - i != ej - j) return ei - i < ej - j;  // "01" before "001": fewer leading zeros first
      i = ei;
      j = ej;
      continue;
    }
    if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
    ++i;
    ++j;
  }
  return a.size() - i < b.size() - j;
}

std::vector<std::string> expand_playlist(const std::vector<std::string>& inputs,
                                         const std::function<void(const std::string&)>& warn) {
  std::vector<std::string> entries;
  for (const std::string& input : inputs) {
    std::error_code ec;
    if (!is_url(input) && fs::is_directory(input, ec)) {
      for (std::string& e : directory_entries(input)) entries.push_back(std::move(e));
    } else if (!is_url(input) && is_m3u_name(input) && fs::is_regular_file(input, ec)) {
      for (std::string& e : m3u_entries(input, warn)) entries.push_back(std::move(e));
    } else {
      entries.push_back(input);
    }
  }
  return entries;
}

}  // namespace nelf
