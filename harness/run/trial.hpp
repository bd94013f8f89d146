// One trial: load the scene, build its query, grow a plant, mesh it, export it, and record what every
// phase cost. The same code path serves `growbench run`, the tests and (later) suites.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "harness/organs/options.hpp"
#include "harness/output/exporters.hpp"
#include "harness/output/mesher.hpp"
#include "harness/record/record.hpp"

namespace growbench {

// The ranges of a trial's numeric settings, checked where they are given (the command line, suite files).
inline constexpr int kMaxThreads = 1024;
inline constexpr double kMaxTimeLimitS = 1e9;  // a deadline in nanoseconds stays within 64 bits
// Metres (a mesh scene with size=0: the file's units). Below a micrometre a float voxel size loses the
// precision OpenVDB's transform needs, and no scene's distance field would fit in memory anyway.
inline constexpr double kMinVoxelSize = 1e-6, kMaxVoxelSize = 1e6;

struct TrialSpec {
  std::string algorithm;
  std::string scene;                      // standard name, *.json, or mesh:PATH
  std::vector<std::string> scene_params;  // key=value
  std::vector<std::string> params;        // algorithm key=value (--set)
  std::uint64_t seed = 1;
  std::vector<glm::vec3> seed_at;  // replaces the scene's seeds, each snapped to the surface
  int max_steps = 5000;            // the step cap for every algorithm
  double time_limit_s = 0.0;       // 0: none; checked between steps
  int threads = 0;                 // 0: all cores
  float voxel_size = 0.0f;         // 0: automatic (see SceneQueryOptions)
  std::string out_dir;             // empty: measure but write no files
  MesherOptions mesher;
  GlbLayout glb = kDefaultGlbLayout;  // the layout of plant.glb (harness/output/exporters.hpp)
  // The organ pass after growth (harness/organs/options.hpp), as key=value; empty: the plant as grown.
  std::vector<std::string> organs;
  // Comparable budgets across algorithms: stop once the plant has this many nodes / this much branch
  // length (0: no budget). Checked after every step.
  std::size_t budget_nodes = 0;
  double budget_length_m = 0.0;
  bool metrics = true;  // compute the quality metrics (harness/output/metrics.hpp)
  // Growth animation: every this many steps (and after the last) the plant is written to
  // OUT/frames/step_NNNNNN.gbplant for `growbench render`, with the images its decals name as
  // step_NNNNNN.IMAGE (0: no frames). The time this takes is recorded and taken out of the growth
  // phase's wall and CPU time.
  int frame_every = 0;
  bool context = true;  // add run_context() to the record (suites record it once instead)
  // Leave the trial's big objects (scene, query, plant, mesh) allocated at the end: for a forked suite
  // child that exits right after, freeing them would only add time the kernel spends again at exit.
  bool skip_teardown = false;
  // For testing the harness only: "crash" (SIGSEGV), "hang", "oom" (allocate until refused) at the
  // start of growth, "throw" (an internal error). Empty in real use.
  std::string fault;
  // Plugin files to load before the trial looks up its algorithm: what a trial's own process (a suite's
  // forked or callgrind child, an A/B side) needs to find a plugin algorithm. Never in results.
  std::vector<std::string> plugins;
};

struct Progress {
  int step = 0;
  std::size_t nodes = 0;
  double growth_seconds = 0.0;
};

// Runs a trial. Bad input throws InputError before any growth; everything else is recorded.
// The returned record is also written to OUT/record.json when out_dir is set.
// `plant_out`, when given, receives the grown plant (tests check invariants on it).
TrialRecord run_trial_record(const TrialSpec& spec, const std::function<void(const Progress&)>& progress = {},
                             Plant* plant_out = nullptr);
// The same record as JSON (to_json of the above).
nlohmann::json run_trial(const TrialSpec& spec, const std::function<void(const Progress&)>& progress = {},
                         Plant* plant_out = nullptr);

// Whether a failure is memory running out, whichever library noticed it: std::bad_alloc, or Embree's
// RTC_ERROR_OUT_OF_MEMORY (as scenes/ reports an Embree error: "Embree: ... (error 4)").
bool is_out_of_memory(const std::exception& e);

// The build and machine this binary runs on (commit and dirty flag, compiler, flags, build type,
// dependency versions, CPU model, cores, date).
RunContext run_context_record();
nlohmann::json run_context();  // to_json of the above

// A TrialSpec as suites hand it to child processes and store it in results (harness/record/record.hpp).
TrialSpecRecord to_record(const TrialSpec& spec);
TrialSpec trial_spec_of(const TrialSpecRecord& record);
nlohmann::json to_json(const TrialSpec& spec);
// InputError naming the JSON path ("the trial spec: at seed: ...") or the file for a bad spec.
TrialSpec trial_spec_from_json(const nlohmann::json& j);
TrialSpec read_trial_spec(const std::string& path);

}  // namespace growbench
