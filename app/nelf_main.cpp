// What nelf's main() does (app/main.cpp): one parse of the command line, one line for a failure.
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <string>
#include <system_error>

#include "app/cli_suggestions.hpp"
#include "app/commands.hpp"
#include "app/config_file.hpp"
#include "app/freed_memory.hpp"
#include "app/nelf_main.hpp"
#include "app/play_command.hpp"
#include "core/printable.hpp"
#include "optics/profile.hpp"

namespace {

// The status of a program that SIGPIPE ended, without the signal: the reader of nelf's output went
// away (`nelf probe --json IN | head -c1`), after nelf cleaned up as for any other failure.
constexpr int broken_pipe_status = 128 + SIGPIPE;

// The one line of a failure. Never throws: stderr may be a closed pipe or a terminal that is gone,
// and a throw from a catch handler would abort nelf instead of returning its status.
// Every message goes through printable(): file names, profile keys and values and metadata in it
// come from outside and may hold newlines or terminal escape sequences.
void print_error_line(const std::string& message) {
  const std::string line = "nelf: " + nelf::printable(message) + "\n";
  std::fwrite(line.data(), 1, line.size(), stderr);
}

}  // namespace

int nelf::app::nelf_main(int argc, char** argv) {
  // A write past the file size limit (`ulimit -f`) would otherwise kill nelf with SIGXFSZ in the
  // middle of a file, leaving it half-written; ignored, the write fails with EFBIG, which every sink
  // reports in one line and cleans up after, as it does for a full disk (ENOSPC).
  std::signal(SIGXFSZ, SIG_IGN);
  // Likewise a write to a pipe nobody reads any more (stdout into `head`, stderr into a closed
  // pager) would kill nelf with SIGPIPE mid-conversion, leaving its temporary output behind.
  // Ignored, the write fails with EPIPE: a diagnostic write is dropped, and EPIPE on an output
  // (stdout, or any sink writing to a pipe) unwinds like any failure, cleaning up, and ends quietly.
  std::signal(SIGPIPE, SIG_IGN);
  nelf::app::keep_freed_memory();  // a live frame's buffers reused, not faulted in anew
  CLI::App app;
  nelf::app::build_cli(app);

  try {
    if (!nelf::app::no_config_requested(argc, argv))
      if (const auto config = nelf::app::config_file_path())
        nelf::app::use_key_rebindings(nelf::app::apply_config_file(app, *config));
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
      print_error_line(*unknown);
    else
      print_error_line(fmt::format("{} (see nelf --help)", e.what()));
    return 2;
  } catch (const nelf::ProfileError& e) {
    print_error_line(e.what());
    return 2;
  } catch (const nelf::app::UserError& e) {
    print_error_line(e.what());
    return e.status();
  } catch (const std::system_error& e) {
    // fmt::print reports a failed write this way (EPIPE when stdout is a closed pipe).
    if (e.code() == std::errc::broken_pipe) return broken_pipe_status;
    print_error_line(fmt::format("error: {}", e.what()));
    return 1;
  } catch (const std::exception& e) {
    print_error_line(fmt::format("error: {}", e.what()));
    return 1;
  }
  // What is still buffered for stdout: a reader that left early is the same quiet end.
  if (std::fflush(stdout) != 0 && errno == EPIPE) return broken_pipe_status;
  return 0;
}
