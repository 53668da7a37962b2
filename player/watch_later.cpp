#include "player/watch_later.hpp"

#include <fmt/format.h>

#include <toml++/toml.h>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <system_error>
#include <type_traits>

#include "core/printable.hpp"
#include "core/state_files.hpp"

namespace nelf {
namespace {

namespace fs = std::filesystem;

// FNV-1a, 64 bits: a stable name for a path (std::hash may change between library versions, and
// would orphan every record). The path is stored in the record too, so a collision is a miss.
std::uint64_t fnv1a(const std::string& text) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

template <class T>
bool read_field(const toml::table& table, const char* key, std::optional<T>& into) {
  const toml::node* node = table.get(key);
  if (!node) return true;
  if constexpr (std::is_same_v<T, double>) {
    const std::optional<double> v = node->value<double>();  // an integer reads as a double too
    if (!v || !(*v >= 0.0)) return false;
    into = *v;
  } else {
    const toml::value<T>* v = node->as<T>();
    if (!v) return false;
    into = v->get();
  }
  return true;
}

}  // namespace

bool WatchLaterRecord::empty() const {
  bool any = false;
  fields([&](const char*, auto member) { any = any || (this->*member).has_value(); });
  return !any;
}

WatchLater::WatchLater(fs::path state_home) {
  if (!state_home.empty()) dir_ = state_home / "nelf" / "watch_later";
}

std::optional<std::string> WatchLater::key_for(const std::string& input) {
  if (input.empty() || input.find("://") != std::string::npos || input.find(':') != std::string::npos) {
    // `synthetic:`, `x11:`, `pipe:`, URLs; a local name with a colon is remembered under `file:`.
    if (input.rfind("file:", 0) != 0) return std::nullopt;
    return key_for(input.substr(5));
  }
  std::error_code ec;
  if (!fs::is_regular_file(input, ec)) return std::nullopt;
  const fs::path path = fs::canonical(input, ec);
  if (ec) return std::nullopt;
  return path.string();
}

fs::path WatchLater::file_for(const std::string& key) const {
  if (dir_.empty()) return {};
  return dir_ / fmt::format("{:016x}.toml", fnv1a(key));
}

WatchLaterRecord WatchLater::load(const std::string& key, const std::function<void(const std::string&)>& warn) const {
  const fs::path file = file_for(key);
  std::error_code ec;
  if (file.empty() || !fs::exists(file, ec)) return {};
  const auto damaged = [&](const std::string& why) {
    warn(fmt::format("{}: the saved state of {} is damaged ({}); starting from the beginning", printable(file.string()),
                     printable(key), why));
    return WatchLaterRecord{};
  };
  toml::table table;
  try {
    table = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    return damaged(std::string(e.description()));
  }
  if (table["path"].value<std::string>() != key) return damaged("it names another file");
  WatchLaterRecord record;
  std::string bad;
  WatchLaterRecord::fields([&](const char* name, auto member) {
    if (!read_field(table, name, record.*member) && bad.empty()) bad = fmt::format("bad value of {}", name);
  });
  if (!bad.empty()) return damaged(bad);
  return record;
}

void WatchLater::save(const std::string& key, const WatchLaterRecord& record,
                      const std::function<void(const std::string&)>& warn) const {
  const fs::path file = file_for(key);
  if (file.empty()) return;
  std::error_code ec;
  if (record.empty()) {
    fs::remove(file, ec);
    return;
  }
  toml::table table;
  table.insert("path", key);
  WatchLaterRecord::fields([&](const char* name, auto member) {
    if ((record.*member).has_value()) table.insert(name, *(record.*member));
  });
  std::ostringstream text;
  text << "# nelf play: where this file was left and how it was set up\n" << table << "\n";
  if (replace_file(file, text.str())) return;
  warn(fmt::format("{}: cannot save where play stopped", printable(file.string())));
}

}  // namespace nelf
