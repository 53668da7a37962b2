#pragma once
// What `nelf play` remembers of each file between runs, as mpv's watch_later does: where the user
// stopped (to resume there) and how they set the file up (the eyes swapped, the layout given), so
// that a file is set up once. One small TOML file per input under $XDG_STATE_HOME/nelf/watch_later/
// (default ~/.local/state), named by a hash of the file's absolute path: a damaged record costs
// that file's only.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace nelf {

struct WatchLaterRecord {
  std::optional<double> position_s;    // where play stopped, in the movie's time
  std::optional<bool> swap_eyes;       // the eyes as the user last had them
  std::optional<std::string> layout;   // --layout as last given
  std::optional<double> sub_parallax;  // the subtitles' depth (--sub-parallax, keys r R) as last left

  // Each field with its key in the file: a new field is a member and one line here.
  template <class Visit>
  static void fields(Visit&& visit) {
    visit("position", &WatchLaterRecord::position_s);
    visit("swap_eyes", &WatchLaterRecord::swap_eyes);
    visit("layout", &WatchLaterRecord::layout);
    visit("sub_parallax", &WatchLaterRecord::sub_parallax);
  }
  bool empty() const;
};

class WatchLater {
 public:
  // The records' folder: `state_home`/nelf/watch_later. `state_home` empty: none (nothing is read
  // or written).
  explicit WatchLater(std::filesystem::path state_home);

  // The key of `input`: its absolute path without symlinks, when it is a local file; nullopt for
  // anything else (URLs, `synthetic:`, a live input), which nelf does not remember.
  static std::optional<std::string> key_for(const std::string& input);

  // The record of `key`, empty when there is none. A record that cannot be read or parsed is
  // reported through `warn` (one line) and read as empty.
  WatchLaterRecord load(const std::string& key, const std::function<void(const std::string&)>& warn) const;
  // Writes the record of `key` (write and rename: a crash leaves the old record or the new one),
  // removing it when `record` is empty. Failure is reported through `warn`: play is over by then.
  void save(const std::string& key, const WatchLaterRecord& record,
            const std::function<void(const std::string&)>& warn) const;
  // The record's file for `key` (the tests damage it).
  std::filesystem::path file_for(const std::string& key) const;

 private:
  std::filesystem::path dir_;
};

}  // namespace nelf
