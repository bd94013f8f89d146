// One growbench subcommand per file in this folder. Each add_NAME registers its subcommand and options on
// the app and returns the function that runs it once the command line is parsed; the options are bound to
// state that function owns. main only builds the app, registers every command, parses and runs the chosen
// one. CLI11 is included only in this folder (a slow header), so here it is only declared.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace growbench::cli {

struct Command {
  CLI::App* app = nullptr;  // the subcommand: true when it was chosen
  // Its exit status. Bad input throws InputError (main exits 2), any other failure another exception (1).
  std::function<int()> run;
};

// Adds --plugin PATH (repeatable), bound to `paths`, to a command that looks algorithms up. The command
// loads them (algorithms/plugins/loader.hpp's load_plugins, which adds GROWBENCH_PLUGIN_PATH's) first
// thing when it runs.
void add_plugin_option(CLI::App* cmd, std::vector<std::string>& paths);

Command add_list(CLI::App& app);
Command add_scenes(CLI::App& app);
Command add_run(CLI::App& app);
Command add_suite(CLI::App& app);
Command add_history(CLI::App& app);  // history add, history plot
Command add_render(CLI::App& app);
Command add_trial(CLI::App& app);  // internal: not listed in --help
Command add_ab(CLI::App& app);
Command add_compare(CLI::App& app);
Command add_merge(CLI::App& app);
Command add_baseline(CLI::App& app);  // baseline update
Command add_report(CLI::App& app);
Command add_lsystem(CLI::App& app);
Command add_summary(CLI::App& app);

}  // namespace growbench::cli
