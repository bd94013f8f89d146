// The deterministic regression gate: two results files (or a committed baseline and a new run) compared
// on what must not change by accident: behaviour (geometry hash, counts, quality metrics), allocations
// (count and bytes per phase), output bytes per format, and instruction counts per phase (from
// `growbench suite --instructions`, callgrind). When both sides are timing runs with repetitions, their
// wall and CPU times are compared too, statistically (harness/stats/stats.hpp), and reported: a timing flag
// never fails here, because it has not been confirmed; `growbench ab` reruns and confirms.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/record/record.hpp"
#include "harness/stats/stats.hpp"

namespace growbench {

struct CompareOptions {
  double instructions_threshold = 0.02;  // a phase's Ir more than this fraction above the base fails ...
  // ... and by more than this many instructions: the smallest phases (a scene load) move a little with the
  // heap layout (path lengths differ between checkouts), and a relative threshold alone would fail them.
  double instructions_floor = 1e5;
  // Allocations may differ by this much per phase without failing. Where code builds absolute paths into
  // the checkout (the bundled meshes, the L-system's example grammars), the checkout's path enters them:
  // its length the bytes, its depth the count, as each std::filesystem::path holds its components. A
  // per-node or per-step regression is far larger.
  double alloc_bytes_slack = 4096;
  double alloc_count_slack = 32;
  double timing_effect = 1.03;  // the statistical comparison's effect size and significance level
  double timing_alpha = 0.01;
};

struct Change {
  std::string cell, quantity;  // e.g. "hadrich/wall/s1", "instructions.growth"
  std::string old_value, new_value;
  double ratio = 0.0;  // new / old for numbers (0 when not numeric)
  bool fails = false;
  std::string why;  // "behaviour", "allocations", "output bytes", "instructions +3.1%", ...
};

struct TimingComparison {
  std::string cell, metric;  // e.g. "growth.wall_s"
  TimingVerdict verdict;
};

struct CompareResult {
  std::vector<TimingComparison> timings;  // both sides with >= 3 ok repetitions
  std::vector<Change> changes;            // every changed quantity, failing or not
  std::size_t cells_compared = 0;
  std::vector<std::string> missing_cells, new_cells;
  std::vector<std::string> plugin_notes;  // plugins of another build, or loaded on one side only
  std::size_t small_changes = 0;          // instruction changes under 0.1% and the floor, counted but not listed
  [[nodiscard]] bool fails() const;
  // A readable table of the changes and a one-line verdict.
  [[nodiscard]] std::string table() const;
};

// What the gate reads on either side: a results file, or a committed baseline.
using GateFile = std::variant<ResultsFile, Baseline>;

CompareResult compare_results(const GateFile& base, const GateFile& now, const CompareOptions& options = {});
// The same on documents read as JSON (each read with from_json; InputError for what is neither).
CompareResult compare_results(const nlohmann::json& base, const nlohmann::json& now,
                              const CompareOptions& options = {});

// The deterministic part of a results file (no timings, no paths): what a committed baseline holds.
Baseline baseline_of(const ResultsFile& results);
nlohmann::json baseline_of(const nlohmann::json& results);

// Reads a results or baseline file; InputError naming the file when it is neither or of a newer schema, and
// naming the JSON path of a field that does not fit.
GateFile read_gate_file(const std::string& path);

}  // namespace growbench
