// growbench summary: the tables of a results file.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "harness/cli/command.hpp"
#include "harness/record/record.hpp"
#include "harness/report/summary.hpp"

namespace growbench::cli {

namespace {

Outcome summarize(const std::string& results_file) {
  // read_results refuses a file of another kind, or one without trials, naming the file and the JSON path.
  fmt::print("{}", summarize_results(read_results(results_file)));
  return Outcome::ok;
}

}  // namespace

Command add_summary(CLI::App& app) {
  auto* cmd = app.add_subcommand("summary", "Print the tables of a results file: per scene, cell by metric");
  auto results_file = std::make_shared<std::string>();
  cmd->add_option("results", *results_file, "results.json written by `growbench suite`")->required();
  return {cmd, [results_file] { return summarize(*results_file); }};
}

}  // namespace growbench::cli
