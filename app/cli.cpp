// The whole command line of nelf, built in one place: main() parses with it, and the packaging's
// generator (packaging/docgen) writes the man page and shell completions from it, so they cannot
// drift from what nelf accepts.
#include <fmt/format.h>

#include "app/commands.hpp"

namespace nelf::app {

namespace {
constexpr CommandRegistrar registrars[] = {
    add_profiles_command, add_design_command, add_convert_command,   add_probe_command,
    add_simulate_command, add_play_command,   add_calibrate_command,
};
}  // namespace

void build_cli(CLI::App& app) {
  app.name("nelf");
  app.description("nelf: watch 3D movies and play stereo games on near-eye light field displays");
  app.set_version_flag("--version", fmt::format("nelf {}", NELF_VERSION));
  app.require_subcommand(1);
  for (auto add : registrars) add(app);
}

}  // namespace nelf::app
