// The whole command line of nelf, built in one place: main() parses with it, and the packaging's
// generator (packaging/docgen) writes the man page and shell completions from it, so they cannot
// drift from what nelf accepts.
#include <fmt/format.h>

#include <cmath>
#include <string>

#include "app/commands.hpp"
#include "app/config_file.hpp"

namespace nelf::app {

namespace {
constexpr CommandRegistrar registrars[] = {
    add_profiles_command, add_design_command, add_convert_command, add_probe_command,
    add_simulate_command, add_play_command,   add_run_command,     add_calibrate_command,
};

// CLI11 reads "nan" and "inf" as numbers; no option of nelf means either (a time, a diameter).
// Applied here to every floating-point option of every command, so that a new one cannot miss it.
void refuse_non_finite_numbers(CLI::App& app) {
  const CLI::Validator finite(
      [](std::string& text) -> std::string {
        double value = 0;
        if (CLI::detail::lexical_cast(text, value) && !std::isfinite(value))
          return "must be a finite number, got " + text;
        return {};
      },
      "");
  for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
    for (CLI::Option* option : command->get_options())
      if (option->get_type_name() == "FLOAT") option->check(finite);
}

}  // namespace

void build_cli(CLI::App& app) {
  app.name("nelf");
  app.description("nelf: watch 3D movies and play stereo games on near-eye light field displays");
  app.set_version_flag("--version", fmt::format("nelf {}", NELF_VERSION));
  app.require_subcommand(1);
  for (auto add : registrars) add(app);
  add_no_config_flag(app);
  refuse_non_finite_numbers(app);
}

}  // namespace nelf::app
