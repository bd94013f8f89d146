// growbench baseline update: accept an intended change into a committed baseline of the regression gate.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "harness/cli/command.hpp"
#include "harness/gate/compare.hpp"
#include "harness/record/files.hpp"
#include "harness/record/record.hpp"

namespace growbench::cli {

namespace {

struct BaselineArgs {
  std::string results, file = "reports/baselines/quick.json";
};

Outcome update_baseline(const BaselineArgs& a) {
  const ResultsFile results = read_results(a.results);
  if (results.mode != "instructions")
    fmt::print(stderr,
               "growbench: warning: {} was not run with --instructions: the baseline will hold no instruction "
               "counts\n",
               a.results);
  const Baseline fresh = baseline_of(results);
  if (std::filesystem::exists(a.file)) {
    const auto r = compare_results(read_gate_file(a.file), fresh, {});
    fmt::print(
        "changes accepted into {}:\n{}", a.file,
        r.changes.empty() && r.missing_cells.empty() && r.new_cells.empty() ? std::string("(none)\n") : r.table());
  } else {
    fmt::print("new baseline {} with {} cells\n", a.file, fresh.trials.size());
  }
  make_directories(std::filesystem::path(a.file).parent_path().string());
  write_file_atomic(a.file, json_text(to_json(fresh), 1));
  return Outcome::ok;
}

}  // namespace

Command add_baseline(CLI::App& app) {
  auto* cmd = app.add_subcommand("baseline", "Manage the committed baselines of the regression gate");
  auto* update = cmd->add_subcommand(
      "update", "Accept an intended change: rewrite the baseline from a results file and print what changed");
  cmd->require_subcommand(1);
  auto a = std::make_shared<BaselineArgs>();
  update->add_option("results", a->results, "results.json of `growbench suite --instructions`")->required();
  update->add_option("--baseline", a->file, "the baseline file to rewrite")
      ->default_val("reports/baselines/quick.json");
  // update is baseline's only subcommand, and one is required.
  return {cmd, [a] { return update_baseline(*a); }};
}

}  // namespace growbench::cli
