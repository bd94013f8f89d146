// growbench suite: run a suite file's trials, each in its own process, and summarise the results.
#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "algorithms/plugins/loader.hpp"
#include "core/errors.hpp"
#include "harness/cli/command.hpp"
#include "harness/gate/history.hpp"
#include "harness/record/record.hpp"
#include "harness/render/render_results.hpp"
#include "harness/report/summary.hpp"
#include "harness/suite/suite.hpp"

namespace growbench::cli {

namespace {

struct SuiteArgs {
  std::string file, out, shard;
  bool resume = false, quiet = false;
  int repetitions = 0, jobs = 0;
  bool instructions = false, plan = false;
  std::string render, history;
  RenderFlags render_flags;
  std::vector<std::string> plugins;
};

// --shard I/N into `o`.
void parse_shard(const std::string& shard, SuiteRunOptions& o) {
  const auto slash = shard.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument("no slash");
    o.shard_index = std::stoi(shard.substr(0, slash));
    o.shard_count = std::stoi(shard.substr(slash + 1));
  } catch (const std::exception&) {
    throw InputError(fmt::format("--shard '{}': expected I/N with 0 <= I < N", shard));
  }
  if (o.shard_count < 1 || o.shard_index < 0 || o.shard_index >= o.shard_count)
    throw InputError(fmt::format("--shard '{}': expected I/N with 0 <= I < N", shard));
}

// Renders every trial of the results directory of `results_path`, then the grid.
void render_suite(const std::string& results_path, const RenderDirOptions& ro) {
  const RenderSummary r = render_directory_record(std::filesystem::path(results_path).parent_path().string(), ro);
  fmt::print("rendered {} trials ({} failed) in {:.0f} s; grid: {}\n", r.renders, r.failed, r.wall_s,
             (std::filesystem::path(results_path).parent_path() / r.grid.value_or("")).string());
}

Outcome run_suite_file(const SuiteArgs& a) {
  // First, while this process is small: the launcher that forks the trials (harness/run/process.hpp).
  std::unique_ptr<Launcher> launcher;
  if (!a.instructions) launcher = start_trial_launcher();
  load_plugins(a.plugins);
  Suite suite = load_suite(a.file);
  if (a.repetitions > 0) suite.repetitions = a.repetitions;
  if (a.plan) {
    fmt::print("{}", plan_text(suite));
    return Outcome::ok;
  }
  SuiteRunOptions o;
  o.launcher = launcher.get();
  o.out_dir = a.out;
  o.resume = a.resume;
  o.quiet = a.quiet;
  o.instructions = a.instructions;
  if (a.jobs > 0 && !a.instructions)
    throw InputError(
        "--jobs runs callgrind trials side by side and needs --instructions: timed trials run one at "
        "a time, so that none disturbs another's timing");
  o.jobs = a.jobs > 0 ? a.jobs : static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
  if (!a.shard.empty()) parse_shard(a.shard, o);
  if (o.instructions)
    fmt::print(
        "suite {}: {} cells, each once, single-threaded, under callgrind (instruction counts per phase), {} at a "
        "time\n",
        suite.name, suite.configs.size(), o.jobs);
  else
    fmt::print("suite {}: {} cells x {} repetitions (+{} warm-up)\n", suite.name, suite.configs.size(),
               suite.repetitions, suite.warmup);
  std::optional<RenderDirOptions> render;  // checked before any trial runs
  if (!a.render.empty()) {
    render.emplace();
    apply_render_flags(a.render_flags, parse_render_quality(a.render, "--render"), *render);
    render->quiet = a.quiet;
  }
  const std::string path = run_suite(suite, o);
  fmt::print("{}", summarize_results(read_results(path)));
  fmt::print("\nwrote {} and results.csv beside it\n", path);
  if (!a.history.empty()) fmt::print("history: appended to {}\n", history_add(path, a.history));
  if (render) render_suite(path, *render);
  return Outcome::ok;
}

}  // namespace

Command add_suite(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "suite", "Run a suite: algorithms x scenes x seeds x sweeps x repetitions, each trial in its own process");
  auto a = std::make_shared<SuiteArgs>();
  cmd->add_option("file", a->file, "suite file (e.g. bench/suites/quick.json)")->required();
  cmd->add_option("-o,--out", a->out, "results directory (default: out/suites/NAME)")
      ->check(path_named("a results folder"));
  add_plugin_option(cmd, a->plugins);
  cmd->add_flag("--resume", a->resume, "continue an interrupted run in --out, skipping finished trials");
  cmd->add_flag("--plan", a->plan,
                "check the suite file and print what it would run (its cells and trials), running nothing");
  cmd->add_option("--shard", a->shard, "run only shard I of N (I/N, 0-based): a deterministic slice of the cells");
  cmd->add_flag("-q,--quiet", a->quiet, "no progress lines");
  cmd->add_option("--repetitions", a->repetitions,
                  "repetitions per cell instead of the suite file's (recorded in results.json; a quicker look "
                  "with wider intervals)")
      ->check(CLI::Range(1, 1000));
  cmd->add_flag("--instructions", a->instructions,
                "run each trial once, single-threaded, under valgrind's callgrind, and record instructions per "
                "phase (the deterministic regression gate: see `growbench compare`)");
  cmd->add_option(
         "-j,--jobs", a->jobs,
         "with --instructions: how many callgrind trials run at once (default: the number of cores; the counts "
         "do not depend on it)")
      ->check(CLI::Range(1, 256));
  CLI::Option* render = cmd->add_option(
      "--render", a->render, "render every trial with POV-Ray afterwards (preview or paper) and compose grid.png");
  add_render_flags(cmd, a->render_flags, render);
  cmd->add_option("--history", a->history,
                  "append the run to this history directory (MACHINE/SUITE/COMMIT.json; see growbench history)");
  return {cmd, [a] { return run_suite_file(*a); }};
}

}  // namespace growbench::cli
