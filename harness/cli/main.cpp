// growbench: the command line. main builds the app, asks each subcommand (one file each, command.hpp) to
// register, parses, and runs the chosen one; the exit status is the command's, 2 on bad input, 1 on any
// other failure.
#include <exception>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/errors.hpp"
#include "harness/cli/command.hpp"

namespace gb = growbench;

int main(int argc, char** argv) {
  CLI::App app{"growbench: grow, measure and compare procedural plant growth algorithms on standard scenes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "growbench 0.1.0");
  // In the order --help lists them (a braced list is evaluated in order).
  namespace cli = gb::cli;
  const cli::Command commands[] = {
      cli::add_list(app),     cli::add_scenes(app), cli::add_run(app),     cli::add_suite(app),   cli::add_history(app),
      cli::add_render(app),   cli::add_trial(app),  cli::add_ab(app),      cli::add_compare(app), cli::add_merge(app),
      cli::add_baseline(app), cli::add_report(app), cli::add_lsystem(app), cli::add_summary(app)};

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints and exits 0; any other command-line error is bad input, status 2 like every other.
    return app.exit(e) == 0 ? 0 : 2;
  }

  try {
    for (const auto& command : commands)
      if (*command.app) return command.run();
  } catch (const gb::InputError& e) {
    fmt::print(stderr, "growbench: error: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "growbench: failed: {}\n", e.what());
    return 1;
  }
  return 0;
}
