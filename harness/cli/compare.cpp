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

Outcome compare_files(const CompareArgs& a) {
  // Both files are read before anything is compared: a file that cannot be read is bad input (2), never a
  // regression (1).
  const GateFile base = read_gate_file(a.base), fresh = read_gate_file(a.fresh);
  const auto r = compare_results(base, fresh, a.options);
  fmt::print("{}", r.table());
  return r.fails() ? Outcome::regression : Outcome::ok;
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
      ->default_val(0.02)
      ->check(number_in(0, 1e6));
  cmd->add_option("--floor", a->options.instructions_floor,
                  "... and by more than this many instructions (tiny phases move with the heap layout)")
      ->default_val(1e5)
      ->check(number_in(0, 1e18));
  return {cmd, [a] { return compare_files(*a); }};
}

}  // namespace growbench::cli
