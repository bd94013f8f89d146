// One trial: load the scene, build its query, grow a plant, mesh it, export it, and record what every
// phase cost. The same code path serves `growbench run`, the tests and (later) suites.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/outcome.hpp"
#include "harness/output/mesher.hpp"
#include "harness/record/record.hpp"

namespace growbench {

struct Scene;

struct Progress {
  int step = 0;
  std::size_t nodes = 0;
  double growth_seconds = 0.0;
};

// Runs a trial. Bad input throws InputError before any growth; everything else is recorded.
// The returned record is also written to OUT/record.json when out_dir is set.
// `plant_out`, when given, receives the grown plant (tests check invariants on it); `scene_out` the scene it
// grew in, with the seeds it grew from, so that a caller judging the plant against it need not load it again.
TrialRecord run_trial_record(const TrialSpec& spec, const std::function<void(const Progress&)>& progress = {},
                             Plant* plant_out = nullptr, Scene* scene_out = nullptr);
// The same record as JSON (to_json of the above).
nlohmann::json run_trial(const TrialSpec& spec, const std::function<void(const Progress&)>& progress = {},
                         Plant* plant_out = nullptr);

// Whether a failure is memory running out, whichever library noticed it: std::bad_alloc, or Embree's
// RTC_ERROR_OUT_OF_MEMORY (as scenes/ reports an Embree error: "Embree: ... (error 4)").
bool is_out_of_memory(const std::exception& e);
// What an exception says of how the work ended: invalid_input for an InputError, plugin_error for a
// PluginError, out_of_memory, else failed.
Outcome outcome_of(const std::exception& e);

// The build and machine this binary runs on (commit and dirty flag, compiler, flags, build type,
// dependency versions, CPU model, cores, date).
// The commit of the source this binary runs from, as run_context_record gives it.
struct SourceCommit {
  std::string commit, dirty = "unknown";
  std::optional<std::int64_t> time;
};
SourceCommit source_commit();
// What --version prints: the version, the source commit (and whether it had changes) and the configured one.
std::string version_line();
RunContext run_context_record();
// /proc/loadavg's 1, 5 and 15 minute load averages, when readable.
std::optional<std::array<double, 3>> load_average();
nlohmann::json run_context();  // to_json of the above

// A trial spec as a suite hands it to a trial's process (harness/record/trial_spec.hpp): InputError naming the JSON
// path ("the trial spec: at seed: ...") or the file for a bad spec.
// Why `fault` (TrialSpec::fault) is not one a trial can inject, or "" when it is (or is empty).
std::string fault_problem(const std::string& fault);
TrialSpec trial_spec_from_json(const nlohmann::json& j);
TrialSpec read_trial_spec(const std::string& path);

}  // namespace growbench
