// `nelf profiles`: the built-in device profiles.
#include <fmt/format.h>
#include <algorithm>

#include "app/commands.hpp"
#include "optics/profile.hpp"

namespace nelf::app {

void add_profiles_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("profiles", "List the built-in device profiles");
  cmd->callback([] {
    std::size_t width = 0;
    for (const auto& p : builtin_profiles()) width = std::max(width, p.name.size());
    for (const auto& p : builtin_profiles()) fmt::print("{:<{}} {}\n", p.name, width, p.description);
  });
}

}  // namespace nelf::app
