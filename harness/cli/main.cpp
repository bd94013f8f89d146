// growbench: the command line. main builds the app, asks each subcommand (one file each, command.hpp) to
// register, parses, and runs the chosen one. It is the one place that turns exceptions into outcomes and
// outcomes into exit statuses (core/outcome.hpp, README "Exit status"): bad input, a plugin's own failure and
// command-line errors 2, anything else, being a bug, 3 with a request for a report.
#include <exception>
#include <functional>
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

gb::Outcome internal_error(const char* what) {
  fmt::print(stderr,
             "growbench: internal error: {}\n"
             "This is a bug in growbench: please report it with the command line and the input that caused it.\n",
             what);
  return gb::Outcome::failed;
}

// Runs the chosen command; an exception becomes the outcome it stands for, its message printed.
gb::Outcome run_command(const gb::cli::Command& command) {
  try {
    return command.run();
  } catch (const gb::InputError& e) {
    fmt::print(stderr, "growbench: error: {}\n", e.what());
    return gb::Outcome::invalid_input;
  } catch (const gb::PluginError& e) {
    fmt::print(stderr,
               "growbench: error: {}\nThis is the plugin's failure, not growbench's (docs/plugins.md says what the "
               "host checks).\n",
               e.what());
    return gb::Outcome::plugin_error;
  } catch (const std::exception& e) {
    const gb::Outcome o = gb::outcome_of(e);
    if (o == gb::Outcome::out_of_memory)
      fmt::print(stderr, "{}{}\n", kOutOfMemory,
                 dynamic_cast<const std::bad_alloc*>(&e) ? "" : fmt::format(" ({})", e.what()));
    return o == gb::Outcome::failed ? internal_error(e.what()) : o;
  } catch (...) {
    return internal_error("an exception of unknown type");
  }
}

// Every repeatable option takes one value per use, as --set and --plugin are documented: CLI11 would let
// `--plugin X.so walker` (or `--plugin=X.so walker`) take the positional `walker` as a second plugin.
void one_value_per_use(CLI::App& app) {
  for (CLI::Option* o : app.get_options())
    if (!o->get_positional()) o->allow_extra_args(false);
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) one_value_per_use(*sub);
}

}  // namespace

int main(int argc, char** argv) {
  namespace cli = gb::cli;
  gb::exit_on_escaped_bad_alloc(gb::exit_status(gb::Outcome::out_of_memory), kOutOfMemory);
  try {
    CLI::App app{"growbench: grow, measure and compare procedural plant growth algorithms on standard scenes"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::function<std::string()>(gb::version_line));
    // Every error the parser finds reads as the commands' own do, and names the help to read.
    app.failure_message([](const CLI::App* a, const CLI::Error& e) {
      std::string help = "growbench";
      for (const CLI::App* sub = a; sub;) {
        const auto chosen = sub->get_subcommands();
        if (chosen.empty()) break;
        sub = chosen.front();
        help += " " + sub->get_name();
      }
      return fmt::format("growbench: error: {}\nRun `{} --help` for more information.\n", e.what(), help);
    });
    // In the order --help lists them (a braced list is evaluated in order).
    const cli::Command commands[] = {
        cli::add_list(app),    cli::add_scenes(app),  cli::add_run(app),         cli::add_suite(app),
        cli::add_history(app), cli::add_render(app),  cli::add_trial(app),       cli::add_ab(app),
        cli::add_compare(app), cli::add_merge(app),   cli::add_baseline(app),    cli::add_report(app),
        cli::add_lsystem(app), cli::add_summary(app), cli::add_plugin_test(app), cli::add_schema(app)};
    one_value_per_use(app);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      // --help and --version print and succeed; any other command-line error is bad usage.
      return gb::exit_status(app.exit(e) == 0 ? gb::Outcome::ok : gb::Outcome::invalid_input);
    }
    for (const auto& command : commands)
      if (*command.app) return command.exit_code(run_command(command));
    return gb::exit_status(gb::Outcome::ok);
  } catch (const std::exception& e) {  // building the command line itself
    return gb::exit_status(internal_error(e.what()));
  }
}
