// `nelf design`: placeholder registration until the design report lands (replaced by the design work).
#include "app/commands.hpp"

namespace nelf::app {
void add_design_command(CLI::App& app) { app.add_subcommand("design", "Optical design figures of a profile"); }
}  // namespace nelf::app
