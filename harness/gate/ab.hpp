// `growbench ab A B SUITE`: the statistical gate. Two growbench binaries (a base and a candidate, built
// elsewhere: ab builds nothing) run the same suite's trials alternately, A B then B A, so drift on a
// shared machine falls on both sides alike. Each cell gets a pilot of repetitions; its measured noise
// (coefficient of variation) then sets how many more it needs to see the effect asked for (--effect), up
// to a cap. Wall and CPU time of the chosen phases are compared with a Mann-Whitney U test and a
// bootstrap interval of the median ratio (harness/stats/stats.hpp), and, because each A ran next to a B,
// with the Wilcoxon signed-rank test of the pairs' ratios: on a shared VM whose speed drifts within
// minutes, drift moves both sides of a pair and cancels in its ratio, while the unpaired test counts it
// as noise. A cell flagged slower or faster is run again, a fresh batch, and only a flag the rerun
// repeats is reported as a regression (exit 1) or an improvement. Noise too high for the effect within
// the cap is reported as "inconclusive", never as "no change".
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/suite/suite.hpp"

namespace growbench {

struct AbOptions {
  std::string a_binary, b_binary;  // growbench executables (each runs `BIN trial SPEC.json`)
  std::string out_dir;             // ab.json and the trials' folders
  double effect = 1.03;            // the smallest median ratio worth reporting
  double alpha = 0.01;             // Mann-Whitney significance level
  double power = 0.8;              // for the repetition count
  int min_repetitions = 6;         // the pilot, per side
  int max_repetitions = 30;        // per side, per batch
  std::vector<std::string> phases = {"growth"};
  bool confirm = true;  // rerun flagged cells
  bool quiet = false;
  // Side B's plugin files instead of those this process loaded: two builds of one plugin, A/B.
  std::vector<std::string> b_plugins;
};

struct AbResult {
  nlohmann::json doc;  // what ab.json holds: options, binaries, every sample, every verdict
  bool regression = false;
  std::string table;  // the readable verdicts
};

AbResult run_ab(const Suite& suite, const AbOptions& options);

}  // namespace growbench
