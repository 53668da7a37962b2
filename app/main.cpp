// nelf: shows stereo content on near-eye light field displays. See README.md.
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <cmath>
#include <csignal>
#include <cstdio>

#include "app/cli_suggestions.hpp"
#include "app/commands.hpp"
#include "compositor/profile.hpp"

namespace {

constexpr nelf::app::CommandRegistrar registrars[] = {
    nelf::app::add_profiles_command,  nelf::app::add_design_command,   nelf::app::add_convert_command,
    nelf::app::add_probe_command,     nelf::app::add_simulate_command, nelf::app::add_play_command,
    nelf::app::add_calibrate_command,
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

int main(int argc, char** argv) {
  // A write past the file size limit (`ulimit -f`) would otherwise kill nelf with SIGXFSZ in the
  // middle of a file, leaving it half-written; ignored, the write fails with EFBIG, which every sink
  // reports in one line and cleans up after, as it does for a full disk (ENOSPC).
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"nelf: watch 3D movies and play stereo games on near-eye light field displays", "nelf"};
  app.set_version_flag("--version", fmt::format("nelf {}", NELF_VERSION));
  app.require_subcommand(1);
  for (auto add : registrars) add(app);
  refuse_non_finite_numbers(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, the way a user can act on it, and the conventional usage-error status. A mistyped
    // command or option is named with the nearest one; CLI11's wording does not name it.
    if (const auto unknown = nelf::app::unknown_argument_message(app, argc, argv))
      fmt::print(stderr, "nelf: {}\n", *unknown);
    else
      fmt::print(stderr, "nelf: {} (see nelf --help)\n", e.what());
    return 2;
  } catch (const nelf::ProfileError& e) {
    fmt::print(stderr, "nelf: {}\n", e.what());
    return 2;
  } catch (const nelf::app::UserError& e) {
    fmt::print(stderr, "nelf: {}\n", e.what());
    return e.status();
  } catch (const std::exception& e) {
    fmt::print(stderr, "nelf: error: {}\n", e.what());
    return 1;
  }
  return 0;
}
