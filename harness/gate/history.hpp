// A history of suite runs across commits, in the spirit of airspeed velocity's results layout:
// DIR/MACHINE/SUITE/COMMIT.json holds every run of that suite at that commit on that machine (a run
// appended per `growbench history add` or `suite --history DIR`), reduced to per-cell medians: growth
// wall and CPU time, the phases' total, peak RSS, nodes, the geometry hash, and (for --instructions
// runs) instructions per phase. `growbench history plot` draws each metric over commits with change
// points marked (reports/history.py).
#pragma once

#include <string>

#include "harness/record/record.hpp"

namespace growbench {

// A machine key from a results context: the CPU model and hardware threads as a file name.
std::string history_machine(const RunContext& context);

// The per-cell summary of one run that a history keeps.
HistoryRun history_entry(const ResultsFile& results);

// Appends the results file's run (a results file, not a baseline) to DIR (machine "" : history_machine of its context).
// Returns the file written. InputError when the results have no commit.
std::string history_add(const std::string& results_path, const std::string& dir, const std::string& machine = "");

// Plots DIR into OUT (reports/history.py); returns its exit status.
int history_plot(const std::string& dir, const std::string& out);

}  // namespace growbench
