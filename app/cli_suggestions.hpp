#pragma once
// "Did you mean": CLI11 reports an unknown subcommand as "A subcommand is required" and an unknown
// flag as "arguments were not expected"; these name the word the user mistyped and the nearest one
// nelf knows.
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace nelf::app {

// Optimal-string-alignment distance: insertions, deletions, substitutions and swaps of two
// neighbouring characters ("stat" -> "start" is 1, "convrt" -> "convert" is 1, "ocnvert" -> "convert" is 1).
std::size_t edit_distance(std::string_view a, std::string_view b);

// The candidate nearest to `word`, when it is near enough to be a typo of it (at most one edit in
// four characters, three at most); nullopt otherwise or when two are equally near.
std::optional<std::string> nearest_word(std::string_view word, const std::vector<std::string>& candidates);

// After CLI11 refused `argv`: the first word of it that names no subcommand of `app` or no option of
// the chosen subcommand, as one line without the "nelf: " prefix ("unknown command 'convrt' (did you
// mean 'convert'?)"); nullopt when every word is known (CLI11's own message says what is wrong).
std::optional<std::string> unknown_argument_message(CLI::App& app, int argc, const char* const* argv);

}  // namespace nelf::app
