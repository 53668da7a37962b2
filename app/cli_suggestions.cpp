#include "app/cli_suggestions.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <numeric>

namespace nelf::app {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  // Three rows of the dynamic programme: the swap looks two rows back.
  std::vector<std::size_t> before(b.size() + 1), previous(b.size() + 1), current(b.size() + 1);
  std::iota(previous.begin(), previous.end(), std::size_t{0});
  for (std::size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitution = a[i - 1] == b[j - 1] ? 0 : 1;
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, previous[j - 1] + substitution});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        current[j] = std::min(current[j], before[j - 2] + 1);
    }
    before.swap(previous);
    previous.swap(current);
  }
  return previous[b.size()];
}

std::optional<std::string> nearest_word(std::string_view word, const std::vector<std::string>& candidates) {
  const auto strip = [](std::string_view w) { return w.substr(std::min(w.find_first_not_of('-'), w.size())); };
  const std::string_view bare = strip(word);
  // Two letters leave too little to tell a typo from another word.
  if (bare.size() < 3) return std::nullopt;
  const std::size_t allowed = std::clamp<std::size_t>(bare.size() / 4, 1, 3);
  std::optional<std::string> best;
  std::size_t best_distance = allowed + 1;
  bool tie = false;
  for (const auto& candidate : candidates) {
    const std::size_t d = edit_distance(bare, strip(candidate));
    if (d < best_distance) {
      best = candidate, best_distance = d, tie = false;
    } else if (d == best_distance && best && *best != candidate) {
      tie = true;
    }
  }
  if (tie) return std::nullopt;
  return best;
}

namespace {

// A word that is an option's value rather than an option: "-1.5", "-0,2".
bool looks_like_number(std::string_view word) {
  return word.size() > 1 && word[0] == '-' && (std::isdigit(static_cast<unsigned char>(word[1])) || word[1] == '.');
}

bool is_option_word(std::string_view word) { return word.size() > 1 && word[0] == '-' && !looks_like_number(word); }

std::vector<std::string> option_names(const CLI::App& cmd) {
  std::vector<std::string> names;
  for (const CLI::Option* option : cmd.get_options()) {
    for (const auto& name : option->get_lnames()) names.push_back("--" + name);
    for (const auto& name : option->get_snames()) names.push_back("-" + name);
  }
  return names;
}

// `word` ("--stat", "--stat=5", "-x") is no option of `cmd`: the line that says so, with the nearest.
std::optional<std::string> unknown_option(const CLI::App& cmd, std::string_view word) {
  std::string name(word.substr(0, word.find('=')));
  if (name.size() > 2 && name[1] != '-') return std::nullopt;  // "-abc": short flags run together
  if (cmd.get_option_no_throw(name) != nullptr) return std::nullopt;
  const std::string where = cmd.get_parent() != nullptr ? cmd.get_name() + ": " : std::string();
  if (const auto near = nearest_word(name, option_names(cmd)))
    return fmt::format("{}unknown option '{}' (did you mean '{}'?)", where, name, *near);
  const std::string help = cmd.get_parent() != nullptr ? "nelf " + cmd.get_name() + " --help" : "nelf --help";
  return fmt::format("{}unknown option '{}' (see {})", where, name, help);
}

}  // namespace

std::optional<std::string> unknown_argument_message(CLI::App& app, int argc, const char* const* argv) {
  const CLI::App* command = nullptr;
  for (int i = 1; i < argc; ++i) {
    const std::string_view word = argv[i];
    if (word == "--") break;  // what follows is positional, whatever it looks like
    if (is_option_word(word)) {
      if (auto message = unknown_option(command != nullptr ? *command : app, word)) return message;
      continue;
    }
    if (command != nullptr) continue;  // an input, an output or an option's value
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
      if (sub->check_name(std::string(word))) {
        command = sub;
        break;
      }
      names.push_back(sub->get_name());
    }
    if (command != nullptr) continue;
    if (const auto near = nearest_word(word, names))
      return fmt::format("unknown command '{}' (did you mean '{}'?)", word, *near);
    return fmt::format("unknown command '{}' (see nelf --help)", word);
  }
  return std::nullopt;
}

}  // namespace nelf::app
