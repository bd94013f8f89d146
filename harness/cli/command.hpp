// One growbench subcommand per file in this folder. Each add_NAME registers its subcommand and options on
// the app and returns the function that runs it once the command line is parsed; the options are bound to
// state that function owns. main only builds the app, registers every command, parses and runs the chosen
// one. CLI11 is included only in this folder (a slow header), so here it is only declared.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "core/outcome.hpp"

namespace CLI {
class App;
class Option;
class Validator;
}  // namespace CLI

namespace growbench {
struct RenderDirOptions;
struct TrialSpec;
enum class RenderQuality;
}  // namespace growbench

namespace growbench::cli {

// How a command ended (core/outcome.hpp); main turns it, or the exception a command throws, into the exit
// status (README, "Exit status"): regression 1, invalid input 2, an internal error 3.
struct Command {
  CLI::App* app = nullptr;  // the subcommand: true when it was chosen
  // How it ended; a failure throws instead (InputError for bad input, anything else is a bug).
  std::function<Outcome()> run;
  // The exit status of each outcome: the command line's contract, except for `trial`, which reports as a
  // trial's process does.
  int (*exit_code)(Outcome) = exit_status;
};

// Checks for numeric options (->check(...)): a value outside is refused before anything runs, with the
// option's name, the range it takes and what was given ("--voxel-size: expected a finite number in [1e-06,
// 1e+06], got 'nan'"), instead of being replaced by another. number_in takes finite numbers from lo (or
// just above it, when lo_open) to hi. integer_in takes whole numbers in [lo, hi]: an unsigned option's
// "-1", which CLI11 would wrap around to the largest value, is refused.
CLI::Validator number_in(double lo, double hi, bool lo_open = false, bool zero_or = false);
CLI::Validator integer_in(long long lo, unsigned long long hi);
// A path given on the command line: not empty (run -o '' wrote into the current folder's default) and
// without control characters, which no file name a report, a render or Slurm writes may carry.
CLI::Validator path_named(const std::string& what);

// Adds the option FLAGS bound to the trial spec's field KEY (harness/record/trial_spec.hpp), checked against
// its declared range or names, with the declaration's doc as help unless `help` is given.
CLI::Option* add_spec_option(CLI::App* cmd, const std::string& flags, TrialSpec& spec, std::string_view key,
                             const std::string& help = "");

// A Python script's exit status (reports/report.py, reports/history.py) under the contract: 0, and 2 for
// bad input, whose message the script printed; anything else (a traceback, a signal) is a bug, said so.
Outcome script_status(int status, const std::string& script);

// Adds --plugin PATH (repeatable), bound to `paths`, to a command that looks algorithms up. The command
// loads them (algorithms/plugins/loader.hpp's load_plugins, which adds GROWBENCH_PLUGIN_PATH's) first
// thing when it runs.
void add_plugin_option(CLI::App* cmd, std::vector<std::string>& paths);

// The options of every command that renders (run --render, suite --render, render): --camera, --dof,
// --backdrop and --turntable, bound to a RenderFlags. When `needs` is given (the command's --render),
// each requires it. apply_render_flags checks them (InputError naming the option: an unknown camera or
// backdrop, a turntable of no frames, depth of field in preview quality) and sets them in `o`; commands
// call it before anything grows or renders.
struct RenderFlags {
  std::string camera = "auto", backdrop = "scene";
  bool dof = false;
  int turntable = 0;
  CLI::Option* turntable_option = nullptr;
};
void add_render_flags(CLI::App* cmd, RenderFlags& flags, CLI::Option* needs = nullptr);
void apply_render_flags(const RenderFlags& flags, RenderQuality quality, RenderDirOptions& o);

Command add_list(CLI::App& app);
Command add_scenes(CLI::App& app);
Command add_run(CLI::App& app);
Command add_suite(CLI::App& app);
Command add_history(CLI::App& app);  // history add, history plot
Command add_render(CLI::App& app);
Command add_trial(CLI::App& app);  // internal: not listed in --help
Command add_ab(CLI::App& app);
Command add_compare(CLI::App& app);
Command add_merge(CLI::App& app);
Command add_baseline(CLI::App& app);  // baseline update
Command add_report(CLI::App& app);
Command add_lsystem(CLI::App& app);
Command add_plugin_test(CLI::App& app);
Command add_summary(CLI::App& app);
Command add_schema(CLI::App& app);  // internal: not listed in --help

}  // namespace growbench::cli
