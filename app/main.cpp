// nelf: shows stereo content on near-eye light field displays. See README.md.
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>

#include "app/commands.hpp"
#include "compositor/profile.hpp"

int main(int argc, char** argv) {
  // A write past the file size limit (`ulimit -f`) would otherwise kill nelf with SIGXFSZ in the
  // middle of a file, leaving it half-written; ignored, the write fails with EFBIG, which every sink
  // reports in one line and cleans up after, as it does for a full disk (ENOSPC).
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app;
  nelf::app::build_cli(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, the way a user can act on it, and the conventional usage-error status.
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
