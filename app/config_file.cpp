#include "app/config_file.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <cstdlib>
#include <string>
#include <system_error>
#include <vector>

#include "app/cli_suggestions.hpp"
#include "core/user_error.hpp"

namespace nelf::app {
namespace {

constexpr std::string_view no_config = "--no-config";

// " (did you mean "output"?)" for the candidate nearest to `word`, " (otherwise)" when none is near.
// `quote` writes a candidate as the file does ("output", [play]).
std::string nearest_hint(const std::string& word, const std::vector<std::string>& candidates,
                         const std::string& otherwise, std::string (*quote)(const std::string&) = nullptr) {
  if (const auto near = nearest_word(word, candidates))
    return fmt::format(" (did you mean {}?)", quote ? quote(*near) : fmt::format("\"{}\"", *near));
  return fmt::format(" ({})", otherwise);
}

// The long options of `command` a configuration file may set: all but --help and --no-config.
std::vector<std::string> settable_options(const CLI::App& command) {
  std::vector<std::string> names;
  for (const CLI::Option* option : command.get_options()) {
    if (option->get_lnames().empty() || option == command.get_help_ptr()) continue;
    const std::string name = option->get_lnames().front();
    if ("--" + name != no_config) names.push_back(name);
  }
  return names;
}

class ConfigReader {
 public:
  explicit ConfigReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const toml::node& node, const std::string& message) const {
    throw UserError(fmt::format("{}:{}: {}", file_, node.source().begin.line, message), 2);
  }

  void apply_command(CLI::App& command, const toml::table& table) const {
    const std::string where = command.get_name();
    const std::vector<std::string> known = settable_options(command);
    for (const auto& [key, node] : table) {
      const std::string name(key.str());
      CLI::Option* option = nullptr;
      for (const std::string& k : known)
        if (k == name) option = command.get_option_no_throw("--" + name);
      if (!option)
        fail(node, fmt::format("unknown key \"{}\" in [{}]{}", name, where,
                               nearest_hint(name, known, fmt::format("see nelf {} --help", where))));
      const std::string value = value_text(node, *option, name, where);
      try {
        option->default_val(value);
      } catch (const CLI::Error& e) {
        fail(node, fmt::format("bad value {} for \"{}\" in [{}]: {}", value, name, where, e.what()));
      }
    }
  }

  KeyRebindings read_keys(const toml::table& table) const {
    KeyRebindings rebindings;
    const std::vector<std::string> commands = [] {
      std::vector<std::string> names = play_command_names();
      names.emplace_back("ignore");
      return names;
    }();
    for (const auto& [key, node] : table) {
      const std::string name(key.str());
      const std::optional<KeyPress> press = parse_key_name(name);
      if (!press)
        fail(node, fmt::format("unknown key name \"{}\" in [keys] (one character, or SPACE, LEFT, RIGHT, UP, DOWN, "
                               "PGUP, PGDWN, ESC, ENTER, TAB, BS, or Ctrl+ and a character)",
                               name));
      const std::optional<std::string> command = node.value_exact<std::string>();
      if (!command)
        fail(node, fmt::format("\"{}\" in [keys] takes a command's name, as a string (e.g. \"swap-eyes\")", name));
      std::optional<Command> bound;
      if (*command != "ignore") {
        bound = command_named(*command);
        if (!bound)
          fail(node, fmt::format("unknown command \"{}\" for \"{}\" in [keys]{}", *command, name,
                                 nearest_hint(*command, commands, "see the key table of nelf play in the README")));
      }
      for (const KeyRebinding& earlier : rebindings)
        if (earlier.key.named == press->named && earlier.key.character == press->character)
          fail(node, fmt::format("\"{}\" in [keys] names a key another line binds", name));
      rebindings.push_back({*press, bound});
    }
    return rebindings;
  }

 private:
  // The value of `node` as the command line would write it, when it is of the type `option` takes.
  std::string value_text(const toml::node& node, const CLI::Option& option, const std::string& name,
                         const std::string& where) const {
    const std::string type = option.get_type_name();
    const auto is = [&](std::string_view prefix) { return type.rfind(prefix, 0) == 0; };
    const auto refuse = [&](std::string_view takes) -> void {
      fail(node, fmt::format("\"{}\" in [{}] takes {}", name, where, takes));
    };
    if (option.get_expected_max() == 0) {  // a flag
      if (const auto b = node.value_exact<bool>()) return *b ? "true" : "false";
      refuse("true or false");
    }
    if (is("INT")) {
      if (const auto i = node.value_exact<std::int64_t>()) return std::to_string(*i);
      refuse("an integer");
    }
    if (is("FLOAT")) {
      if (const auto i = node.value_exact<std::int64_t>()) return std::to_string(*i);
      if (const auto d = node.value_exact<double>()) return fmt::format("{}", *d);
      refuse("a number");
    }
    if (const auto s = node.value_exact<std::string>()) return *s;
    refuse("a string");
    return {};
  }

  std::string file_;
};

}  // namespace

std::optional<std::filesystem::path> config_file_path() {
  const char* xdg = std::getenv("XDG_CONFIG_HOME");
  if (xdg && *xdg) return std::filesystem::path(xdg) / "nelf" / "nelf.toml";
  const char* home = std::getenv("HOME");
  if (home && *home) return std::filesystem::path(home) / ".config" / "nelf" / "nelf.toml";
  return std::nullopt;
}

bool no_config_requested(int argc, const char* const* argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--") return false;
    if (arg == no_config) return true;
  }
  return false;
}

void add_no_config_flag(CLI::App& app) {
  for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; })) {
    // The value is no_config_requested()'s; the flag is here to be accepted and documented.
    command->add_flag(std::string(no_config))->description("Ignore the configuration file (~/.config/nelf/nelf.toml)");
  }
}

KeyRebindings apply_config_file(CLI::App& app, const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return {};
  const std::string file = path.string();
  toml::table root;
  try {
    root = toml::parse_file(file);
  } catch (const toml::parse_error& e) {
    if (e.source().begin.line == 0)  // not the text: the file itself
      throw UserError(fmt::format("{}: {}", file, e.description()), 2);
    throw UserError(fmt::format("{}:{}: TOML syntax error: {}", file, e.source().begin.line, e.description()), 2);
  }
  const ConfigReader reader(file);
  std::vector<std::string> tables{"keys"};
  for (const CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
    tables.push_back(command->get_name());
  KeyRebindings rebindings;
  for (const auto& [key, node] : root) {
    const std::string name(key.str());
    const toml::table* table = node.as_table();
    if (!table)
      reader.fail(node,
                  fmt::format("\"{}\" is not in a table: options go in their command's ([play], [convert], …)", name));
    if (name == "keys") {
      rebindings = reader.read_keys(*table);
      continue;
    }
    CLI::App* command = nullptr;
    for (CLI::App* c : app.get_subcommands([](CLI::App*) { return true; }))
      if (c->get_name() == name) command = c;
    if (!command)
      reader.fail(node, fmt::format("unknown table [{}]{}", name,
                                    nearest_hint(name, tables, "tables are commands' names, and [keys]",
                                                 [](const std::string& t) { return "[" + t + "]"; })));
    reader.apply_command(*command, *table);
  }
  return rebindings;
}

}  // namespace nelf::app
