// growbench summary: the tables of a results file.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/errors.hpp"
#include "harness/cli/command.hpp"
#include "harness/record/files.hpp"
#include "harness/report/summary.hpp"

namespace growbench::cli {

namespace {

int summarize(const std::string& results_file) {
  const nlohmann::json results = read_json_file(results_file);
  if (!results.contains("trials") || results.value("kind", "") != "growbench-results")
    throw InputError(fmt::format("{}: not a growbench results file (no kind/trials)", results_file));
  fmt::print("{}", summarize_results(results));
  return 0;
}

}  // namespace

Command add_summary(CLI::App& app) {
  auto* cmd = app.add_subcommand("summary", "Print the tables of a results file: per scene, cell by metric");
  auto results_file = std::make_shared<std::string>();
  cmd->add_option("results", *results_file, "results.json written by `growbench suite`")->required();
  return {cmd, [results_file] { return summarize(*results_file); }};
}

}  // namespace growbench::cli
