#pragma once
// Language tags as files carry them (ISO 639-2: "eng", "ger") matched against what a user asks for
// (--alang, --slang): in any case, as mpv matches them.
#include <cctype>
#include <string_view>

namespace nelf {

inline bool same_language_tag(std::string_view tagged, std::string_view asked) {
  if (tagged.size() != asked.size()) return false;
  for (std::size_t i = 0; i < tagged.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(tagged[i])) != std::tolower(static_cast<unsigned char>(asked[i])))
      return false;
  return true;
}

}  // namespace nelf
