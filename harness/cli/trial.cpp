// growbench trial (internal): one trial from a spec file written by a suite, in this process.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "harness/cli/command.hpp"
#include "harness/run/trial.hpp"
#include "harness/suite/suite.hpp"

namespace growbench::cli {

namespace {

struct TrialArgs {
  std::string spec_file, fault;
};

Outcome run_spec(const TrialArgs& a) {
  TrialSpec ts = read_trial_spec(a.spec_file);  // errors name the spec file and the JSON path
  if (!a.fault.empty()) ts.fault = a.fault;
  return run_trial_child(ts, ts.out_dir);
}

}  // namespace

Command add_trial(CLI::App& app) {
  auto* cmd = app.add_subcommand("trial", "Run one trial from a spec file written by a suite (internal)");
  cmd->group("");  // not listed in --help: suites call it under callgrind
  auto a = std::make_shared<TrialArgs>();
  cmd->add_option("spec", a->spec_file, "spec.json")->required();
  // Test hook: a wrapper script that appends `--fault slow:N` turns this binary into a planted slowdown
  // for `growbench ab` (tests/harness/ab_test.sh).
  cmd->add_option("--fault", a->fault, "inject a fault into the trial (tests)");
  // Not the command line's contract: it reports to the suite or ab that ran it as a trial's process does.
  return {cmd, [a] { return run_spec(*a); }, trial_exit_code};
}

}  // namespace growbench::cli
