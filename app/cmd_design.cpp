// `nelf design`: the optical design figures of a profile (DESIGN.md §2), as a table or JSON, and
// optionally the trade-space plot of Lanman & Luebke's Fig. 5.
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>

#include "analysis/design_plot.hpp"
#include "app/commands.hpp"
#include "optics/design.hpp"
#include "optics/profile.hpp"
#include "player/input_files.hpp"

namespace nelf::app {

namespace {
struct DesignOptions {
  std::string profile = "hmz-t1";
  bool json = false;
  std::string plot_path;
};

void run_design(const DesignOptions& options) {
  if (!options.plot_path.empty()) {
    InputFiles inputs;
    inputs.add(options.profile, "the --profile");
    inputs.refuse_as_output(options.plot_path);
  }
  const Profile profile = load_profile(options.profile);
  const DesignReport report = design_report(profile);
  // Plot first: if the file cannot be written, nothing is printed and the status says so.
  if (!options.plot_path.empty()) {
    try {
      write_trade_space_plot(profile, options.plot_path);
    } catch (const PlotError& e) {
      throw UserError(e.what(), 1);
    }
  }
  if (options.json)
    fmt::print("{}\n", design_to_json(report).dump(2));
  else
    fmt::print("{}", design_table(report));
}
}  // namespace

void add_design_command(CLI::App& app) {
  auto options = std::make_shared<DesignOptions>();
  auto* cmd = app.add_subcommand("design", "Optical design figures of a profile (field of view, resolution, eye box…)");
  cmd->footer(
      "Figures follow Lanman & Luebke, \"Near-Eye Light Field Displays\" (2013); see docs/optics.md.\n"
      "Profiles without [lens_array] report the panel only, or the single-lens model when they have [magnifier].");
  cmd->add_option("--profile", options->profile, "Built-in profile name or TOML file")
      ->capture_default_str()
      ->type_name("NAME|FILE");
  cmd->add_flag("--json", options->json, "Print one JSON object instead of the table");
  cmd->add_option("--plot", options->plot_path,
                  "Also write the resolution trade-space plot (f × w_l, Fig. 5 style) to this PNG file")
      ->type_name("FILE.png");
  cmd->callback([options] { run_design(*options); });
}

}  // namespace nelf::app
