#pragma once
// What mpv's JSON IPC asks of `nelf play` (--input-ipc-server), answered as mpv answers it, so
// that mpv's remotes and scripts drive nelf: {"command": ["seek", 10, "relative"], "request_id": 7}
// → {"data": …, "error": "success", "request_id": 7}. Commands (quit, seek, cycle, set,
// set_property, get_property, keypress, playlist-next, playlist-prev) and properties (pause,
// time-pos, duration, percent-pos, filename, path, volume, mute, sid/sub, aid/audio) are tables (ipc_commands.cpp):
// another is one row. Everything they change goes through PlayCommands, as the keys do. A line that is not JSON is a
// command as mpv's input.conf writes it ("cycle pause"), run without a reply, as mpv does.
#include <optional>
#include <string>
#include <string_view>

#include "player/key_bindings.hpp"
#include "player/play_commands.hpp"

namespace nelf::playback {

// What the requests read and change: the state the play loop keeps, and its commands.
struct IpcTarget {
  PlayState& state;
  PlayCommands& commands;
  std::optional<double> duration_s;
  std::string path;  // the input as given
  const KeyRebindings& keys;
  std::optional<PlayEnd> end;  // set by quit, or by a key that ends play (quit, another file)
};

// The reply line to `line` (without newlines); "" for a text command, which mpv does not answer.
std::string answer_ipc_request(std::string_view line, IpcTarget& target);

}  // namespace nelf::playback
