// growbench: the command line. main builds the app, asks each subcommand (one file each, command.hpp) to
// register, parses, and runs the chosen one. It is the one place that turns exceptions into exit statuses
// (command.hpp's ExitStatus, README "Exit status"): bad input and command-line errors 2, anything else,
// being a bug, 3 with a request for a report.
#include <exception>
#include <new>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/errors.hpp"
#include "harness/cli/command.hpp"
#include "harness/run/process.hpp"
#include "harness/run/trial.hpp"

namespace gb = growbench;

namespace {

constexpr const char* kOutOfMemory =
    "growbench: error: out of memory: the input asks for more memory than this process may use";

int internal_error(const char* what) {
  fmt::print(stderr,
             "growbench: internal error: {}\n"
             "This is a bug in growbench: please report it with the command line and the input that caused it.\n",
             what);
  return gb::cli::kExitInternalError;
}

}  // namespace

int main(int argc, char** argv) {
  namespace cli = gb::cli;
  gb::exit_on_escaped_bad_alloc(cli::kExitBadInput, kOutOfMemory);
  try {
    CLI::App app{"growbench: grow, measure and compare procedural plant growth algorithms on standard scenes"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "growbench 0.1.0");
    // In the order --help lists them (a braced list is evaluated in order).
    const cli::Command commands[] = {cli::add_list(app),    cli::add_scenes(app),   cli::add_run(app),
                                     cli::add_suite(app),   cli::add_history(app),  cli::add_render(app),
                                     cli::add_trial(app),   cli::add_ab(app),       cli::add_compare(app),
                                     cli::add_merge(app),   cli::add_baseline(app), cli::add_report(app),
                                     cli::add_lsystem(app), cli::add_summary(app)};
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      // --help and --version print and succeed; any other command-line error is bad usage.
      return app.exit(e) == 0 ? cli::kExitOk : cli::kExitBadInput;
    }
    for (const auto& command : commands)
      if (*command.app) return command.run();
    return cli::kExitOk;
  } catch (const gb::InputError& e) {
    fmt::print(stderr, "growbench: error: {}\n", e.what());
    return cli::kExitBadInput;
  } catch (const std::exception& e) {
    if (gb::is_out_of_memory(e)) {
      fmt::print(stderr, "{}{}\n", kOutOfMemory,
                 dynamic_cast<const std::bad_alloc*>(&e) ? "" : fmt::format(" ({})", e.what()));
      return cli::kExitBadInput;
    }
    return internal_error(e.what());
  } catch (...) {
    return internal_error("an exception of unknown type");
  }
}
