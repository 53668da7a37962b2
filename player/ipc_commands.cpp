#include "player/ipc_commands.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <sstream>
#include <vector>

namespace nelf::playback {

namespace {

using json = nlohmann::json;

// mpv's error strings, which clients compare against.
constexpr const char* success = "success";
constexpr const char* invalid_parameter = "invalid parameter";
constexpr const char* property_not_found = "property not found";
constexpr const char* property_unavailable = "property unavailable";

struct Reply {
  const char* error = success;
  std::optional<json> data;
};

// A value mpv's commands take as a number: a JSON number or the text of one.
std::optional<double> number(const json& value) {
  if (value.is_number()) return value.get<double>();
  if (!value.is_string()) return std::nullopt;
  const std::string text = value.get<std::string>();
  std::size_t used = 0;
  try {
    const double d = std::stod(text, &used);
    if (used == text.size()) return d;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

// A flag as mpv takes it: true/false, or "yes"/"no".
std::optional<bool> flag(const json& value) {
  if (value.is_boolean()) return value.get<bool>();
  if (value == "yes") return true;
  if (value == "no") return false;
  return std::nullopt;
}

// Where play is: the frame on screen, or where a seek goes until its first frame shows (as mpv
// answers at once after a seek).
double time_pos(const IpcTarget& t) {
  if (t.state.awaiting_seek) return t.state.seek_target_s;
  return t.state.current ? t.state.current->pts_s : 0.0;
}

struct Property {
  std::string_view name;
  // nullopt: there is no value now ("property unavailable"); a property without get is write-only.
  std::optional<json> (*get)(IpcTarget&);
  // false: the value is not one the property takes ("invalid parameter"); null: read-only.
  bool (*set)(IpcTarget&, const json&);
  // cycle's step through a choice (+1, or -1 for "down"); null: a flag, which cycle toggles.
  void (*cycle)(IpcTarget&, int step);
};

// A track id as mpv gives it: its number, or false for none.
json track_id(int number) { return number > 0 ? json(number) : json(false); }

// A track id as mpv takes it: a number from 1 (or its text), or false / "no" for none (0).
std::optional<int> track_number(const json& value) {
  if (const std::optional<bool> off = flag(value); off && !*off) return 0;
  const std::optional<double> n = number(value);
  if (!n || *n < 1 || *n != std::floor(*n) || *n > 1e6) return std::nullopt;
  return static_cast<int>(*n);
}

std::optional<json> subtitle_track_id(IpcTarget& t) { return track_id(t.commands.subtitle_track()); }
bool set_subtitle_track_id(IpcTarget& t, const json& v) {
  const std::optional<int> n = track_number(v);
  return n && t.commands.set_subtitle_track(*n);
}
void cycle_subtitle_track(IpcTarget& t, int step) {
  t.commands.apply(step > 0 ? Command::next_subtitle_track : Command::previous_subtitle_track);
}

std::optional<json> audio_track_id(IpcTarget& t) { return track_id(t.commands.audio_track()); }
bool set_audio_track_id(IpcTarget& t, const json& v) {
  const std::optional<int> n = track_number(v);
  return n && *n > 0 && t.commands.set_audio_track(*n);
}
void cycle_audio_track(IpcTarget& t, int step) {
  const int count = t.commands.audio_track_count();
  if (count < 2) {
    t.commands.apply(Command::next_audio_track);  // says why nothing changes
    return;
  }
  t.commands.set_audio_track((t.commands.audio_track() - 1 + step + count) % count + 1);
}

const Property properties[] = {
    {"pause", [](IpcTarget& t) -> std::optional<json> { return t.state.paused; },
     [](IpcTarget& t, const json& v) {
       const std::optional<bool> paused = flag(v);
       if (!paused) return false;
       if (*paused != t.state.paused) t.commands.apply(Command::pause);
       return true;
     },
     nullptr},
    {"time-pos", [](IpcTarget& t) -> std::optional<json> { return time_pos(t); },
     [](IpcTarget& t, const json& v) {
       const std::optional<double> to = number(v);
       if (!to) return false;
       t.commands.seek_shown(*to);
       return true;
     },
     nullptr},
    {"duration",
     [](IpcTarget& t) -> std::optional<json> {
       if (!t.duration_s) return std::nullopt;
       return *t.duration_s;
     },
     nullptr, nullptr},
    {"percent-pos",
     [](IpcTarget& t) -> std::optional<json> {
       if (!t.duration_s || *t.duration_s <= 0) return std::nullopt;
       return 100.0 * time_pos(t) / *t.duration_s;
     },
     nullptr, nullptr},
    {"filename", [](IpcTarget& t) -> std::optional<json> { return std::filesystem::path(t.path).filename().string(); },
     nullptr, nullptr},
    {"path", [](IpcTarget& t) -> std::optional<json> { return t.path; }, nullptr, nullptr},
    {"volume", [](IpcTarget& t) -> std::optional<json> { return t.commands.volume(); },
     [](IpcTarget& t, const json& v) {
       const std::optional<double> to = number(v);
       if (!to || *to < 0 || *to > 130) return false;  // --volume's range
       t.commands.set_volume(*to);
       return true;
     },
     nullptr},
    {"mute", [](IpcTarget& t) -> std::optional<json> { return t.commands.muted(); },
     [](IpcTarget& t, const json& v) {
       const std::optional<bool> mute = flag(v);
       if (!mute) return false;
       t.commands.set_mute(*mute);
       return true;
     },
     nullptr},
    // mpv's track ids: a number, false for none. sub and audio are mpv's other names for them.
    {"sid", subtitle_track_id, set_subtitle_track_id, cycle_subtitle_track},
    {"sub", subtitle_track_id, set_subtitle_track_id, cycle_subtitle_track},
    {"aid", audio_track_id, set_audio_track_id, cycle_audio_track},
    {"audio", audio_track_id, set_audio_track_id, cycle_audio_track},
};

const Property* property_named(const json& name) {
  if (!name.is_string()) return nullptr;
  for (const Property& p : properties)
    if (p.name == name.get<std::string>()) return &p;
  return nullptr;
}

Reply set_property(IpcTarget& t, const std::vector<json>& args) {
  if (args.size() != 2) return {invalid_parameter, {}};
  const Property* p = property_named(args[0]);
  if (!p) return {property_not_found, {}};
  if (!p->set || !p->set(t, args[1])) return {invalid_parameter, {}};
  return {};
}

// `command` carried out as its key does; the first reason to end play it gives is kept.
Reply as_key(IpcTarget& t, Command command) {
  if (const std::optional<PlayEnd> end = t.commands.apply(command); end && !t.end) t.end = end;
  return Reply{};
}

struct IpcCommand {
  std::string_view name;
  Reply (*run)(IpcTarget&, const std::vector<json>& args);
};

const IpcCommand commands[] = {
    {"quit",
     [](IpcTarget& t, const std::vector<json>&) {
       t.end = PlayEnd::quit_key;
       return Reply{};
     }},
    // The keys' > and <: at the playlist's end mpv stays on the file and says so, as they do.
    {"playlist-next", [](IpcTarget& t, const std::vector<json>&) { return as_key(t, Command::next_file); }},
    {"playlist-prev", [](IpcTarget& t, const std::vector<json>&) { return as_key(t, Command::previous_file); }},
    {"get_property",
     [](IpcTarget& t, const std::vector<json>& args) {
       if (args.size() != 1) return Reply{invalid_parameter, {}};
       const Property* p = property_named(args[0]);
       if (!p || !p->get) return Reply{property_not_found, {}};
       std::optional<json> value = p->get(t);
       if (!value) return Reply{property_unavailable, {}};
       return Reply{success, std::move(value)};
     }},
    {"set_property", set_property},
    {"set", set_property},
    {"cycle",
     [](IpcTarget& t, const std::vector<json>& args) {
       if (args.empty() || args.size() > 2) return Reply{invalid_parameter, {}};
       const Property* p = property_named(args[0]);
       if (!p) return Reply{property_not_found, {}};
       if (p->cycle) {
         if (args.size() == 2 && args[1] != "up" && args[1] != "down") return Reply{invalid_parameter, {}};
         p->cycle(t, args.size() == 2 && args[1] == "down" ? -1 : 1);
         return Reply{};
       }
       const std::optional<json> now = p->get ? p->get(t) : std::nullopt;
       if (!now || !now->is_boolean() || !p->set) return Reply{invalid_parameter, {}};
       p->set(t, !now->get<bool>());
       return Reply{};
     }},
    {"seek",
     [](IpcTarget& t, const std::vector<json>& args) {
       if (args.empty() || args.size() > 3) return Reply{invalid_parameter, {}};
       const std::optional<double> amount = number(args[0]);
       if (!amount) return Reply{invalid_parameter, {}};
       std::string mode = "relative";
       if (args.size() >= 2) {
         if (!args[1].is_string()) return Reply{invalid_parameter, {}};
         mode = args[1].get<std::string>();
         // mpv's precision flags: nelf's seeks are always exact (to the frame).
         for (const std::string_view exact : {"+exact", "+keyframes"})
           if (mode.size() > exact.size() && mode.ends_with(exact)) mode.resize(mode.size() - exact.size());
       }
       if (mode == "relative") {
         t.commands.seek_by(*amount);
       } else if (mode == "absolute") {
         t.commands.seek_shown(*amount);
       } else if (mode == "absolute-percent" || mode == "relative-percent") {
         if (!t.duration_s) return Reply{property_unavailable, {}};
         const double s = *amount / 100.0 * *t.duration_s;
         if (mode == "absolute-percent")
           t.commands.seek_shown(s);
         else
           t.commands.seek_by(s);
       } else {
         return Reply{invalid_parameter, {}};
       }
       return Reply{};
     }},
    {"keypress",
     [](IpcTarget& t, const std::vector<json>& args) {
       if (args.size() != 1 || !args[0].is_string()) return Reply{invalid_parameter, {}};
       const std::optional<KeyPress> key = parse_key_name(args[0].get<std::string>());
       if (!key) return Reply{invalid_parameter, {}};
       // The key as if typed: the same binding table, rebindings and commands.
       if (const std::optional<Command> command = command_for(KeyScope::play, *key, t.keys)) return as_key(t, *command);
       return Reply{};
     }},
};

Reply run(IpcTarget& t, const std::vector<json>& words) {
  if (words.empty() || !words[0].is_string()) return {invalid_parameter, {}};
  for (const IpcCommand& c : commands)
    if (c.name == words[0].get<std::string>()) return c.run(t, std::vector<json>(words.begin() + 1, words.end()));
  return {invalid_parameter, {}};
}

}  // namespace

std::string answer_ipc_request(std::string_view line, IpcTarget& target) {
  const std::size_t first = line.find_first_not_of(" \t");
  if (first == std::string_view::npos) return "";
  if (line[first] != '{') {
    std::vector<json> words;
    std::istringstream in{std::string(line)};
    for (std::string word; in >> word;) words.emplace_back(word);
    run(target, words);
    return "";
  }
  json reply = json::object();
  const json request = json::parse(line, nullptr, false);
  if (request.is_discarded() || !request.is_object()) {
    reply["error"] = invalid_parameter;
    return reply.dump();
  }
  // mpv's own: the request's id comes back, 0 when it had none.
  reply["request_id"] = request.contains("request_id") ? request["request_id"] : json(0);
  const auto command = request.find("command");
  if (command == request.end() || !command->is_array()) {
    reply["error"] = invalid_parameter;
    return reply.dump();
  }
  Reply answer = run(target, command->get<std::vector<json>>());
  if (answer.data) reply["data"] = std::move(*answer.data);
  reply["error"] = answer.error;
  return reply.dump();
}

}  // namespace nelf::playback
