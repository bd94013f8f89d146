// One growbench subcommand per file in this folder. Each add_NAME registers its subcommand and options on
// the app and returns the function that runs it once the command line is parsed; the options are bound to
// state that function owns. main only builds the app, registers every command, parses and runs the chosen
// one. CLI11 is included only in this folder (a slow header), so here it is only declared.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
class Option;
class Validator;
}  // namespace CLI

namespace growbench {
struct RenderDirOptions;
enum class RenderQuality;
}  // namespace growbench

namespace growbench::cli {

// The exit-status contract (README, "Exit status"). main is the one place that maps exceptions to it: an
// InputError or a command-line error is kExitBadInput, any other exception kExitInternalError.
enum ExitStatus : int {
  kExitOk = 0,
  kExitRegression = 1,     // compare or ab found a regression; nothing else exits 1
  kExitBadInput = 2,       // bad input or usage, or an output path that cannot be written
  kExitInternalError = 3,  // a bug: an unexpected exception, or a tool growbench runs failing on its own files
};

struct Command {
  CLI::App* app = nullptr;  // the subcommand: true when it was chosen
  // Its exit status; a failure throws instead (InputError for bad input, anything else is a bug).
  std::function<ExitStatus()> run;
};

// Checks for numeric options (->check(...)): a value outside is refused before anything runs, with the
// option's name, the range it takes and what was given ("--voxel-size: expected a finite number in [1e-06,
// 1e+06], got 'nan'"), instead of being replaced by another. number_in takes finite numbers from lo (or
// just above it, when lo_open) to hi. integer_in takes whole numbers in [lo, hi]: an unsigned option's
// "-1", which CLI11 would wrap around to the largest value, is refused.
CLI::Validator number_in(double lo, double hi, bool lo_open = false);
CLI::Validator integer_in(long long lo, unsigned long long hi);

// A Python script's exit status (reports/report.py, reports/history.py) under the contract: 0, and 2 for
// bad input, whose message the script printed; anything else (a traceback, a signal) is a bug, said so.
ExitStatus script_status(int status, const std::string& script);

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
Command add_summary(CLI::App& app);

}  // namespace growbench::cli
