// growbench ab: the statistical gate between two growbench binaries.
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "algorithms/plugins/loader.hpp"
#include "harness/cli/command.hpp"
#include "harness/gate/ab.hpp"
#include "harness/suite/suite.hpp"

namespace growbench::cli {

namespace {

struct AbArgs {
  AbOptions options;
  std::string suite;
  std::vector<std::string> plugins;
  bool no_confirm = false;
};

Outcome run_ab_suite(const AbArgs& a) {
  load_plugins(a.plugins);  // each side's trials load them again: their specs list every plugin loaded
  const Suite suite = load_suite(a.suite);
  AbOptions o = a.options;
  o.confirm = !a.no_confirm;
  const AbResult r = run_ab(suite, o);
  fmt::print("{}", r.table);
  return r.regression ? Outcome::regression : Outcome::ok;
}

}  // namespace

Command add_ab(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "ab",
      "The statistical gate: run a suite's trials with two growbench binaries alternately (A B, B A, ...) and "
      "report, per cell, whether B is slower, faster, unchanged, or the noise is too high to tell; exit 1 only "
      "on a slowdown that a rerun confirms");
  auto a = std::make_shared<AbArgs>();
  AbOptions& o = a->options;
  cmd->add_option("a", o.a_binary, "the base growbench binary")->required();
  cmd->add_option("b", o.b_binary, "the candidate growbench binary")->required();
  cmd->add_option("suite", a->suite, "suite file (its cells, seeds and limits; its repetitions are not used)")
      ->required();
  add_plugin_option(cmd, a->plugins);
  cmd->add_option("--plugin-b", o.b_plugins,
                  "side B loads this plugin file instead of --plugin's and the suite's (repeatable): A/B of two "
                  "builds of one plugin");
  cmd->add_option("-o,--out", o.out_dir, "output directory: ab.json and the trials (default: out/ab/SUITE)")
      ->check(path_named("an output folder"));
  cmd->add_option("--effect", o.effect, "the smallest median ratio B/A to detect")
      ->default_val(1.03)
      ->check(number_in(1, 100, true));
  cmd->add_option("--alpha", o.alpha, "significance level of the Mann-Whitney U test")
      ->default_val(0.01)
      ->check(number_in(0, 1, true));
  cmd->add_option("--min-reps", o.min_repetitions, "pilot repetitions per side")
      ->default_val(6)
      ->check(integer_in(3, 1000));
  cmd->add_option("--max-reps", o.max_repetitions,
                  "at most this many per side and batch; noisier cells are 'inconclusive'")
      ->default_val(30)
      ->check(integer_in(3, 1000));
  cmd->add_option("--phases", o.phases, "phases whose wall and CPU time are compared")
      ->default_val(std::vector<std::string>{"growth"})
      ->delimiter(',');
  cmd->add_flag("--no-confirm", a->no_confirm, "do not rerun flagged cells (a flag is then 'unconfirmed')");
  cmd->add_flag("-q,--quiet", o.quiet, "no progress lines");
  return {cmd, [a] { return run_ab_suite(*a); }};
}

}  // namespace growbench::cli
