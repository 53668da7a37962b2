// `nelf profiles`: the built-in device profiles.
#include <fmt/format.h>

#include "app/commands.hpp"
#include "optics/profile.hpp"

namespace nelf::app {

void add_profiles_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("profiles", "List the built-in device profiles");
  cmd->callback([] {
    for (const auto& p : builtin_profiles()) fmt::print("{:<14} {}\n", p.name, p.description);
  });
}

}  // namespace nelf::app
