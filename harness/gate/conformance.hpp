// The conformance checks every built-in algorithm passes on every standard scene (tests/algorithms,
// EveryAlgorithmEveryScene), as one function an outside author runs on a plugin: `growbench plugin-test`.
// Each trial runs in its own forked process, so a plugin that crashes or hangs fails its check and the
// rest still run.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace growbench {

struct ConformanceOptions {
  std::vector<std::string> params;  // key=value, after the algorithm's test_params
  int max_steps = 3000;             // as the built-ins' tests grow
  double timeout_s = 300.0;         // per trial process
  double cancel_after_s = 0.05;     // the time limit of the cancellation trial
  double cancel_grace_s = 2.0;      // how long past it growth may go on (one step that never asks)
};

struct ConformanceCheck {
  std::string name;  // "grows", "valid plant", "one tree per seed", "no node inside a solid", ...
  bool pass = false;
  std::string detail;  // what was seen
};

struct SceneConformance {
  std::string scene;
  std::vector<ConformanceCheck> checks;
  [[nodiscard]] bool pass() const;
};

// Runs `algorithm` (built-in or loaded plugin) on `scene` four times, each in a fresh process: on one thread,
// on two, on one again, and on two under a short time limit. Checks that it grows a valid plant (finite,
// parents before children, unit organ turns) of one tree per seed with no node inside a solid; that one and
// two threads, and two runs, grow the same plant bit for bit; and that the time limit (host->cancelled())
// stops growth within cancel_grace_s, keeping a valid plant. The algorithm's test_params apply to all but
// the last, which grows with its defaults so that it lasts past the limit. Must be called before this process starts
// any thread (it forks).
SceneConformance check_conformance(const std::string& algorithm, const std::string& scene,
                                   const ConformanceOptions& options);

}  // namespace growbench
