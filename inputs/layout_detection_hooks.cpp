#include "inputs/layout_detection_hooks.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <vector>

#include "inputs/stereo_metadata.hpp"

namespace nelf {

namespace {

std::vector<std::string> lowercase_tokens(std::string_view path) {
  const std::string name = std::filesystem::path(std::string(path)).stem().string();
  std::vector<std::string> tokens;
  std::string current;
  for (char c : name) {
    if (std::isalnum(static_cast<unsigned char>(c)) != 0) {
      current += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!current.empty()) {
      tokens.push_back(current);
      current.clear();
    }
  }
  if (!current.empty()) tokens.push_back(current);
  return tokens;
}

}  // namespace

std::optional<LayoutHint> layout_hint_from_filename(std::string_view path, double frame_display_aspect) {
  const std::vector<std::string> tokens = lowercase_tokens(path);
  const std::string side_by_side = frame_display_aspect >= kFullSideBySideMinAspect ? "sbs" : "sbs-half";
  // Release names write "h-sbs" or "half.ou" as two tokens; "hsbs" as one.
  static const std::map<std::string, std::string> pairs = {
      {"full-sbs", "sbs"},     {"h-sbs", "sbs-half"},    {"half-sbs", "sbs-half"},
      {"h-tab", "tab-half"},   {"half-tab", "tab-half"}, {"h-ou", "tab-half"},
      {"half-ou", "tab-half"}, {"full-ou", "tab"},       {"full-tab", "tab"},
  };
  static const std::map<std::string, std::string> singles = {
      {"sbs", "sbs"},  {"fsbs", "sbs"}, {"hsbs", "sbs-half"}, {"tab", "tab"},      {"ou", "tab"},
      {"ftab", "tab"}, {"fou", "tab"},  {"htab", "tab-half"}, {"hou", "tab-half"},
  };
  for (std::size_t i = 0; i + 1 < tokens.size(); ++i)
    if (auto it = pairs.find(tokens[i] + "-" + tokens[i + 1]); it != pairs.end()) return LayoutHint{it->second, false};
  for (const auto& token : tokens) {
    if (auto it = singles.find(token); it != singles.end()) return LayoutHint{it->second, false};
    if (token == "lr") return LayoutHint{side_by_side, false};
    if (token == "rl") return LayoutHint{side_by_side, true};
  }
  if (std::find(tokens.begin(), tokens.end(), "3d") != tokens.end()) return LayoutHint{"sbs-half", false};
  return std::nullopt;
}

std::optional<LayoutHint> layout_hint_from_aspect(double frame_display_aspect) {
  if (frame_display_aspect >= 3.0) return LayoutHint{"sbs", false};
  if (frame_display_aspect > 0.0 && frame_display_aspect <= 1.0) return LayoutHint{"tab", false};
  return std::nullopt;
}

}  // namespace nelf
