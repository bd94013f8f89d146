// Suites: a matrix of algorithms x scenes x seeds x parameter sweeps x repetitions, each trial run in
// its own (forked) process with a timeout and an address-space limit. Every finished repetition is
// appended to OUT/journal.jsonl (flushed before the next trial); results.json and results.csv are
// rewritten atomically every 10 s and at the end. --resume replays the journal, so an interrupted suite
// (even by kill -9) loses at most the trial in flight.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/run/process.hpp"
#include "harness/run/trial.hpp"

namespace growbench {

// The most cells a suite may have. Sweeps multiply: a suite of a billion cells would run out of memory long
// before its first trial, so it is refused as its file is read; a study that large is several suites.
inline constexpr std::size_t kMaxSuiteCells = 100000;

struct SuiteConfig {       // one cell of the matrix (run `repetitions` times)
  std::string id;          // label/scene/seed/sweep, unique in the suite; also the trial's folder name
  std::string label;       // the algorithm entry's label (the algorithm's name unless the suite gives one)
  std::string scene_name;  // the scene's display name (its own name unless the suite gives one)
  nlohmann::json sweep = nlohmann::json::object();  // the swept parameters' values for this cell
  TrialSpec spec;
};

struct Suite {
  std::string name, file, hash, description;
  int repetitions = 3;
  int warmup = 1;
  double timeout_s = 600.0;
  std::uint64_t memory_limit_bytes = 16ull << 30;
  std::vector<SuiteConfig> configs;  // in run order: interleaved across algorithm entries
};

// Reads and validates a suite file: every algorithm, scene and parameter (and every swept value) is
// checked before anything runs; an error names the file and the JSON path.
Suite load_suite(const std::string& path);

// What a suite runs, counted: its matrix and its trials (cells x repetitions, and the warm-ups). What
// `growbench suite --plan` prints, and what the README's figures about the standard suite are checked against.
struct SuitePlan {
  std::size_t cells = 0, entries = 0, scenes = 0, seeds = 0, sweep_points = 0;
  int repetitions = 0, warmup = 0;
  std::size_t trials = 0;  // cells x repetitions + warm-ups
};
SuitePlan plan_of(const Suite& suite);
// "NAME: 240 cells (8 algorithm entries x 10 scenes x 3 seeds), 5 repetitions each and 1 warm-up: 1201
// trials", then each cell's id on a line.
std::string plan_text(const Suite& suite);

struct SuiteRunOptions {
  std::string out_dir;  // default: out/suites/NAME
  bool resume = false;
  int shard_index = 0, shard_count = 1;  // run configs with (index % count) == shard_index
  bool quiet = false;
  // Run each trial once, single-threaded, under valgrind's callgrind, recording instructions per phase
  // ("instructions" in each cell): the deterministic measure the regression gate compares.
  bool instructions = false;
  // With `instructions`: how many callgrind trials run at once (their counts do not depend on it).
  int jobs = 1;
  // Forks the trials (timing mode). Null: run_suite starts one. `growbench suite` starts it first thing,
  // before the suite file is read, so trials inherit as little of this process as possible.
  Launcher* launcher = nullptr;
};

// A cell's trial as a suite runs it, as the JSON a trial's process reads (the launcher's job, or the
// spec.json of `growbench trial`): into DIR, without the context (recorded once per suite), and without
// teardown (the process exits right after).
nlohmann::json trial_job(const SuiteConfig& cell, const std::string& dir);

// Readies this process for forking trials (stops library threads, warms TBB) and starts a launcher whose
// jobs are trials (a job is the JSON {"spec", "dir"} run_suite sends).
std::unique_ptr<Launcher> start_trial_launcher();

// The body of a trial's own process: runs the trial into DIR (record.json) and returns how it ended, which
// the process reports as trial_exit_code (core/outcome.hpp; error.txt says why it failed). When
// report_fd >= 0 it writes "STARTED FINISHED" there (steady-clock nanoseconds: when the body began, and
// when record.json was in place) with one write, for the suite's overhead accounting.
// `growbench trial SPEC.json` calls it too (the callgrind mode runs trials that way), without a report.
Outcome run_trial_child(const TrialSpec& spec, const std::string& dir, int report_fd = -1);

// Runs the suite and returns the path of results.json. Throws InputError if results already exist
// and resume is off.
std::string run_suite(const Suite& suite, const SuiteRunOptions& options);

// Joins the results of the shards of one suite run (`--shard I/N`, every I from 0 to N-1, the same suite
// file) into one results document whose trials are in the unsharded run's order: identical to an
// unsharded run apart from timings and the context (the first shard's; all of them under "shards").
// Throws InputError naming the file that does not fit (another suite, a missing or repeated shard), and
// for shards whose machines or builds differ (CPU model, hardware threads, binary hash): their timings
// cannot be compared with each other, so that takes `mixed_machines`, and the merged context then says so.
ResultsFile merge_results(const std::vector<ResultsFile>& shards, const std::vector<std::string>& names,
                          bool mixed_machines = false);
// The same on results read as JSON (each read with from_json, errors naming names[k]); a file without a
// "shard" key is refused.
nlohmann::json merge_results(const std::vector<nlohmann::json>& shards, const std::vector<std::string>& names,
                             bool mixed_machines = false);

}  // namespace growbench
