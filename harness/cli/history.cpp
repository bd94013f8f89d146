// growbench history add, growbench history plot: suite runs across commits.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "harness/cli/command.hpp"
#include "harness/gate/history.hpp"

namespace growbench::cli {

namespace {

struct HistoryArgs {
  std::string results, dir = "out/history", machine, out = "out/history-report";
};

}  // namespace

Command add_history(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "history", "Suite runs across commits: append runs to a history directory, plot each metric over commits");
  cmd->require_subcommand(1);
  auto a = std::make_shared<HistoryArgs>();
  auto* add = cmd->add_subcommand("add", "Append a results file's run (keyed by its commit and machine)");
  add->add_option("results", a->results, "results.json of growbench suite")->required();
  add->add_option("--dir", a->dir, "the history directory")->default_val("out/history");
  add->add_option("--machine", a->machine, "machine name (default: from the CPU model and thread count)");
  auto* plot = cmd->add_subcommand(
      "plot", "Plot every metric over commits per machine and suite, change points marked (PNG, PDF, index.html)");
  plot->add_option("--dir", a->dir, "the history directory")->default_val("out/history");
  plot->add_option("-o,--out", a->out, "output directory")
      ->check(path_named("an output folder"))
      ->default_val("out/history-report");
  return {cmd, [a, add] {
            if (*add) {
              fmt::print("appended to {}\n", history_add(a->results, a->dir, a->machine));
              return Outcome::ok;
            }
            return script_status(history_plot(a->dir, a->out), "reports/history.py");
          }};
}

}  // namespace growbench::cli
