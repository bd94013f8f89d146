// growbench compare: two results files (or a baseline), the deterministic regression gate.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "harness/cli/command.hpp"
#include "harness/gate/compare.hpp"

namespace growbench::cli {

namespace {

struct CompareArgs {
  std::string base, fresh;
  CompareOptions options;
};

int compare_files(const CompareArgs& a) {
  const auto r = compare_results(read_results_file(a.base), read_results_file(a.fresh), a.options);
  fmt::print("{}", r.table());
  return r.fails() ? 1 : 0;
}

}  // namespace

Command add_compare(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "compare",
      "Compare two results files (or a baseline): behaviour, allocations, output bytes, instructions; exit 1 "
      "on a regression");
  auto a = std::make_shared<CompareArgs>();
  cmd->add_option("base", a->base, "the base: a results.json or a baseline (reports/baselines/*.json)")->required();
  cmd->add_option("new", a->fresh, "the new results.json")->required();
  cmd->add_option("--threshold", a->options.instructions_threshold,
                  "fail when a phase's instruction count rises by more than this fraction")
      ->default_val(0.02);
  cmd->add_option("--floor", a->options.instructions_floor,
                  "... and by more than this many instructions (tiny phases move with the heap layout)")
      ->default_val(1e5);
  return {cmd, [a] { return compare_files(*a); }};
}

}  // namespace growbench::cli
