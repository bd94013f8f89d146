// What the harness writes, declared once: a trial's record (record.json of `growbench run` and of a suite's
// trial), the suite's journal lines and results file (results.json), its baseline, and a history file. Each
// struct has one to_json and one from_json; every reader and writer of these files goes through them, in the
// spirit of Google Benchmark's one `Run` record that each reporter serialises.
//
// Reading is tolerant of absence and strict about everything else. A field missing from the file reads as
// its default (or as empty, for the std::optional members, whose absence means something: a failed sample
// has no phases), so partial and hand-written files stay readable. A field of the wrong type, or one this
// harness does not know (a renamed field), is an InputError naming the file and the JSON path:
// "results.json: at trials[3].samples[0].phases.growth.wall_s: expected a number". What the suite always
// writes is required by the JSON Schema beside this file (results.schema.json), which the tests and
// reports/report.py check files against.
//
// Open-ended parts stay JSON: algorithm parameters, metrics by name, sweep values, library versions.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/plugin_origin.hpp"

namespace growbench {

// The version of every document below. A field is only ever added; renaming or retyping one bumps this,
// and the readers keep reading the older version. reports/report.py reads it from results.schema.json.
inline constexpr int kSchemaVersion = 1;
inline constexpr std::string_view kResultsKind = "growbench-results";
inline constexpr std::string_view kBaselineKind = "growbench-baseline";
inline constexpr std::string_view kHistoryKind = "growbench-history";

// ---------------------------------------------------------------- a trial

// What one phase of a trial cost (harness/run/trial.cpp measures it).
struct PhaseMeasures {
  double wall_s = 0.0, cpu_s = 0.0;
  std::uint64_t peak_rss_bytes = 0;  // the phase's own peak (VmHWM, reset at its start)
  bool peak_rss_reset = false;       // whether that reset worked (else the peak is the process's so far)
  std::uint64_t alloc_count = 0, alloc_bytes = 0;
  // query_build only: its parts and the distance field's size.
  std::optional<double> bvh_s, sdf_s;
  std::optional<std::uint64_t> sdf_active_voxels;
  std::optional<double> voxel_size_m;
  // growth with --frames only: the frame capture's time, already taken out of wall_s and cpu_s.
  std::optional<double> frame_capture_wall_s, frame_capture_cpu_s;
};

// A trial's phases, each absent when it did not run (metrics with metrics off; all of them in a hand-written
// sample). `exporting` is the JSON's "export" (a C++ keyword).
struct Phases {
  std::optional<PhaseMeasures> scene_load, query_build, growth, organs, meshing, exporting, metrics;
  // The phase of that JSON name, or null (absent or unknown).
  [[nodiscard]] const PhaseMeasures* find(std::string_view name) const;
  [[nodiscard]] PhaseMeasures* find(std::string_view name);
  // Calls f(name, measures) for each present phase in the order of their names, as the JSON holds them
  // (sums over phases then add in the same order as before the record was typed).
  template <class F>
  void each(F&& f) const {
    for (const std::string_view name : kNames)
      if (const PhaseMeasures* p = find(name)) f(name, *p);
  }
  static constexpr std::array<std::string_view, 7> kNames = {"export", "growth",      "meshing",   "metrics",
                                                             "organs", "query_build", "scene_load"};
};

struct Counts {
  std::uint64_t nodes = 0, segments = 0, leaves = 0, organs = 0, polygons = 0, mesh_vertices = 0, mesh_triangles = 0;
  friend bool operator==(const Counts&, const Counts&) = default;
};

// Bytes written per output format; empty when the trial wrote no files.
struct OutputBytes {
  std::optional<std::uint64_t> obj, ply, glb, skeleton_obj, skeleton_ply;
  // The bytes plant.glb would have in the plain layout (docs/metrics.md), computed without writing it.
  std::optional<std::uint64_t> glb_plain;
  // The files only the algorithm makes (GrowthAlgorithm::write_outputs), by name; absent when none.
  std::map<std::string, std::uint64_t> algorithm_files;
};

// The growth curve: a bounded number of points, thinned by doubling `every` (kCurveCap in harness/run/trial.cpp).
struct Curve {
  int every = 1;
  std::vector<int> step;
  std::vector<std::uint64_t> nodes, organs;
  std::vector<double> wall_s;
};

// The scene as the trial loaded it.
struct SceneInfo {
  std::string spec, name, hash;
  std::uint64_t triangles = 0, seeds = 0;
  std::vector<std::string> params;  // key=value
};

struct FramesInfo {
  int every = 0, count = 0;
  std::string dir;  // relative to the trial's directory
};

// The build and machine a run used (run_context_record() in harness/run/trial.hpp).
struct RunContext {
  std::string growbench_commit = "unknown";
  std::string dirty = "unknown";            // "true", "false" or "unknown"
  std::optional<std::int64_t> commit_time;  // committer time (Unix seconds); written as null when unknown
  std::string configured_commit, build_type, compiler, cxx_flags, binary_hash, cpu_model, date;
  std::uint64_t hardware_threads = 0;
  bool alloc_counting = false;
  nlohmann::json dependencies = nlohmann::json::object();  // library -> version
  // Suites only: the suite file's hash, and the threads of the process that forked the trials.
  std::optional<std::string> suite_file_hash;
  std::optional<int> parent_threads_at_fork;
  std::optional<bool> mixed_machines;  // merged shards that ran on different machines or builds
  // Every plugin loaded: a result says exactly what ran (absent when there were none).
  std::vector<PluginOrigin> plugins;
};

// One render (growbench render): harness/render/render.hpp's RenderResult and how it was made. Paths are
// relative to the results (or run) directory.
struct RenderRecord {
  std::string status;  // ok | failed | timeout | no_povray
  std::optional<std::string> message;
  std::vector<std::string> warnings;
  std::string png, pov, log;
  int width = 0, height = 0;
  std::uint64_t pov_bytes = 0;
  double write_s = 0.0, wall_s = 0.0, cpu_s = 0.0;
  std::string quality, branches;
  int threads = 0;
  // The camera it used, "scene" or "fitted" (harness/render/camera.hpp), and the plant's projected extent
  // with the scene's camera, the figure its auto rule judged; the backdrop (scene | studio) and whether it
  // had depth of field.
  std::optional<std::string> camera, backdrop;
  std::optional<double> scene_extent;
  std::optional<bool> dof;
};

// The growth animation made from a trial's frames, or a turntable (the camera orbiting the plant).
struct AnimationRecord {
  std::string status;  // ok | failed | no_ffmpeg
  std::uint64_t frames = 0;
  std::optional<std::string> frame_pattern, message, file;
  std::optional<std::uint64_t> bytes;
};

// record.json: one trial (run_trial in harness/run/trial.hpp).
// The organ pass after growth (harness/organs/): its settings and what placement did.
struct OrganPassRecord {
  nlohmann::json options = nlohmann::json::object();  // every organ option with its effective value
  std::uint64_t placed = 0, fallen_back = 0, dropped = 0;
};

struct TrialRecord {
  int schema_version = kSchemaVersion;
  std::string status = "ok";
  std::string algorithm;
  std::uint64_t seed = 1;
  std::uint64_t threads = 0;  // the threads it ran with
  int max_steps = 0;
  Phases phases;
  SceneInfo scene;
  nlohmann::json params = nlohmann::json::object();  // the algorithm's effective parameters by name
  std::optional<std::string> leaf_obj;
  std::optional<OrganPassRecord> organs;  // only when the pass ran (an organ option was given)
  std::optional<FramesInfo> frames;
  int steps = 0;
  std::string stopped_by;
  Curve curve;
  std::optional<std::uint64_t> snapshot_bytes;  // plant.gbplant, when the trial wrote files
  std::optional<nlohmann::json> metrics;        // by name (harness/output/metrics.hpp); absent with metrics off
  Counts counts;
  double total_length_m = 0.0;
  OutputBytes output_bytes;
  std::string geometry_hash;
  std::map<std::string, double> algorithm_stats;
  std::uint64_t peak_rss_bytes = 0;    // the whole process's, never reset
  std::optional<RunContext> context;   // absent in a suite's trials (the suite records it once)
  std::optional<RenderRecord> render;  // added by growbench render
  std::optional<AnimationRecord> animation;
  std::optional<AnimationRecord> turntable;  // growbench render --turntable N: turntable/frame_NNNN.png
};

// A trial as a suite hands it to its process and stores it in results (harness/run/trial.hpp's TrialSpec,
// serialised).
struct TrialSpecRecord {
  std::string algorithm, scene;
  std::vector<std::string> scene_params, params;  // key=value
  std::uint64_t seed = 1;
  std::vector<std::array<double, 3>> seed_at;
  int max_steps = 5000;
  double time_limit_s = 0.0;
  int threads = 0;
  double voxel_size = 0.0;
  int sides = 6;
  std::uint64_t budget_nodes = 0;
  double budget_length_m = 0.0;
  bool metrics = true;
  int frame_every = 0;
  std::string fault;
  std::optional<std::string> leaf_obj;             // only when given: older specs stay as they were
  std::optional<std::vector<std::string>> organs;  // --organ key=value; only when given
  std::optional<std::string> glb;                  // --glb layout; only when not the default
  // Only in the job a suite sends a trial's process (never in results).
  std::optional<std::string> out_dir;
  std::optional<bool> context, skip_teardown;
  std::optional<std::vector<std::string>> plugins;  // every plugin the writing process had loaded
};

// ---------------------------------------------------------------- a suite

using InstructionCounts = std::map<std::string, std::uint64_t>;  // phase -> instructions (callgrind)

struct AllocCount {
  std::uint64_t count = 0, bytes = 0;
};
using AllocByPhase = std::map<std::string, AllocCount>;

// One repetition of a cell (a journal line's "sample", an entry of a cell's "samples").
struct SuiteSample {
  int repetition = 0;
  std::string status;  // ok | crashed | timeout | out_of_memory | invalid_input
  std::optional<std::string> message;
  double child_wall_s = 0.0, child_user_s = 0.0, child_system_s = 0.0;
  std::uint64_t child_max_rss_bytes = 0;
  std::optional<Phases> phases;  // ok samples
  std::optional<int> steps;
  std::optional<InstructionCounts> instructions;  // --instructions
  // Where the time outside the phases went (timing mode; harness/suite/suite.cpp).
  std::optional<double> outside_phases_s, launch_s, launch_fork_s, child_bookkeeping_s, teardown_s, parent_s,
      harness_overhead_s;
};

// The per-cell fields, taken from the cell's first successful repetition. In a journal line after the first
// success, only geometry_hash and counts (compared, to catch nondeterminism).
struct CellResults {
  std::optional<std::string> geometry_hash;
  std::optional<Counts> counts;
  std::optional<OutputBytes> output_bytes;
  std::optional<nlohmann::json> metrics;  // by name
  std::optional<double> total_length_m;
  std::optional<int> steps;
  std::optional<std::string> stopped_by;
  std::optional<Curve> curve;
  std::optional<nlohmann::json> params;  // by name
  std::optional<std::map<std::string, double>> algorithm_stats;
  std::optional<std::uint64_t> threads;
  std::optional<std::string> scene_hash;
  std::optional<AllocByPhase> alloc;
  std::optional<InstructionCounts> instructions;
  std::optional<OrganPassRecord> organs;  // the organ pass's counts, when it ran
};

// A median and its distribution-free 95% interval (median_interval in harness/stats/stats.hpp).
struct MedianSummary {
  std::uint64_t n = 0;  // samples
  double median = 0.0, lo = 0.0, hi = 0.0;
  bool exact = false;  // false: fewer than 6 samples, [lo, hi] is the full range
};

// Statistics of a cell's ok repetitions, computed by the suite so that reports do not compute them again.
struct CellSummary {
  std::optional<MedianSummary> growth_s;  // the growth phase's wall time
};

// A line of journal.jsonl: one finished repetition, durable before the next trial starts.
struct JournalEntry {
  std::string id;
  SuiteSample sample;
  std::optional<CellResults> cell;  // null unless the repetition succeeded
};

// An entry of results.json "trials": one cell of the suite's matrix with its repetitions.
struct SuiteCell {
  std::string id, label, algorithm, scene, scene_spec;
  std::uint64_t seed = 1;
  nlohmann::json sweep = nlohmann::json::object();  // the swept parameters' values
  TrialSpecRecord spec;
  std::string status = "pending";  // ok, or the last failed repetition's status
  std::optional<std::string> message;
  std::optional<bool> nondeterministic;  // two repetitions grew different plants
  std::vector<SuiteSample> samples;
  CellResults results;  // written into the cell's own object
  std::optional<CellSummary> summary;
  std::optional<RenderRecord> render;
  std::optional<AnimationRecord> animation;
  std::optional<AnimationRecord> turntable;  // growbench render --turntable N: turntable/frame_NNNN.png
};

struct SuiteInfo {
  std::string name, file, description;
};

struct ShardInfo {
  int index = 0, count = 1;
};

// A merged file's record of one shard.
struct ShardRecord {
  int index = 0;
  std::string file;
  RunContext context;
};

// The renders of a results directory (growbench render).
struct RenderSummary {
  std::string quality, branches, povray;
  int width = 0, height = 0, jobs = 0, threads_per_render = 0;
  std::uint64_t renders = 0, ok = 0, failed = 0, warnings = 0, skipped_without_snapshot = 0;
  double povray_s = 0.0, wall_s = 0.0;
  std::optional<std::string> grid, grid_error;
  std::optional<std::map<std::string, std::string>> grid_per_scene;  // scene -> image
  std::optional<std::string> camera, backdrop;                       // as asked: auto | scene, scene | studio
  std::optional<bool> dof;
  std::optional<std::uint64_t> turntable;  // frames per trial
};

// Growth time over the seeds of one algorithm entry (and sweep point) on one scene: the rows of the
// report's table.
struct PooledSummary {
  std::string label, scene;
  nlohmann::json sweep = nlohmann::json::object();
  std::vector<std::string> cells;  // the ok cells pooled
  MedianSummary growth_s;
};

struct ResultsSummary {
  std::vector<PooledSummary> growth_s_over_seeds;
};

// results.json.
struct ResultsFile {
  int schema_version = kSchemaVersion;
  std::string kind = std::string(kResultsKind);
  std::string mode = "timing";  // timing | instructions
  SuiteInfo suite;
  std::string suite_hash;
  int repetitions = 0;
  ShardInfo shard;
  RunContext context;
  std::vector<SuiteCell> trials;
  std::optional<std::vector<ShardRecord>> shards;  // merged files
  std::optional<RenderSummary> renders;
  std::optional<ResultsSummary> summary;
};

// ---------------------------------------------------------------- the gate and the history

struct BaselineContext {
  std::string growbench_commit, dirty, compiler, cxx_flags, build_type;
  nlohmann::json dependencies = nlohmann::json::object();
};

// A cell as a baseline keeps it: what the regression gate compares, no timings.
struct BaselineCell {
  std::string id, label, algorithm, scene;
  std::uint64_t seed = 1;
  std::string status;
  std::optional<std::uint64_t> threads;
  std::optional<std::string> geometry_hash;
  std::optional<Counts> counts;
  std::optional<nlohmann::json> metrics;
  std::optional<OutputBytes> output_bytes;
  std::optional<AllocByPhase> alloc;
  std::optional<InstructionCounts> instructions;
};

// reports/baselines/*.json.
struct Baseline {
  int schema_version = kSchemaVersion;
  std::string kind = std::string(kBaselineKind);
  std::string mode = "timing";
  SuiteInfo suite;
  std::string suite_hash;
  BaselineContext context;
  std::vector<BaselineCell> trials;
};

// A cell of one run in a history file: medians over its ok repetitions (harness/gate/history.hpp).
struct HistoryCell {
  std::string status;
  std::optional<std::string> geometry_hash;
  std::optional<std::uint64_t> nodes;
  // Timing runs only, each with its sample count.
  std::optional<double> total_wall_s, growth_wall_s, growth_cpu_s, growth_peak_rss_bytes;
  std::optional<std::uint64_t> total_wall_s_n, growth_wall_s_n, growth_cpu_s_n, growth_peak_rss_bytes_n;
  std::optional<InstructionCounts> instructions;
};

struct HistoryRun {
  std::string date, mode, dirty, build_type;
  std::map<std::string, HistoryCell> cells;  // by cell id
};

// DIR/MACHINE/SUITE/COMMIT.json.
struct HistoryFile {
  std::string kind = std::string(kHistoryKind);
  int schema_version = kSchemaVersion;
  std::string commit;
  std::optional<std::int64_t> commit_time;  // written as null when unknown
  std::string machine, cpu_model, suite;
  std::uint64_t hardware_threads = 0;
  std::vector<HistoryRun> runs;
};

// ---------------------------------------------------------------- serialising

nlohmann::json to_json(const PhaseMeasures& v);
nlohmann::json to_json(const Phases& v);
nlohmann::json to_json(const Counts& v);
nlohmann::json to_json(const OutputBytes& v);
nlohmann::json to_json(const Curve& v);
nlohmann::json to_json(const SceneInfo& v);
nlohmann::json to_json(const FramesInfo& v);
nlohmann::json to_json(const OrganPassRecord& v);
nlohmann::json to_json(const RunContext& v);
nlohmann::json to_json(const RenderRecord& v);
nlohmann::json to_json(const AnimationRecord& v);
nlohmann::json to_json(const TrialRecord& v);
nlohmann::json to_json(const TrialSpecRecord& v);
nlohmann::json to_json(const AllocCount& v);
nlohmann::json to_json(const SuiteSample& v);
nlohmann::json to_json(const CellResults& v);
nlohmann::json to_json(const MedianSummary& v);
nlohmann::json to_json(const CellSummary& v);
nlohmann::json to_json(const JournalEntry& v);
nlohmann::json to_json(const SuiteCell& v);
nlohmann::json to_json(const SuiteInfo& v);
nlohmann::json to_json(const ShardInfo& v);
nlohmann::json to_json(const ShardRecord& v);
nlohmann::json to_json(const RenderSummary& v);
nlohmann::json to_json(const PooledSummary& v);
nlohmann::json to_json(const ResultsSummary& v);
nlohmann::json to_json(const ResultsFile& v);
nlohmann::json to_json(const BaselineContext& v);
nlohmann::json to_json(const BaselineCell& v);
nlohmann::json to_json(const Baseline& v);
nlohmann::json to_json(const HistoryCell& v);
nlohmann::json to_json(const HistoryRun& v);
nlohmann::json to_json(const HistoryFile& v);

// T from JSON read from `source` (a file name, for errors). Throws InputError "SOURCE: at PATH: WHAT" for a
// value of the wrong type or an unknown field. Defined for every struct above.
template <class T>
T from_json(const nlohmann::json& j, const std::string& source);

// ---------------------------------------------------------------- the files

// Each reads and parses PATH (InputError "PATH:LINE:COL: invalid JSON" or "PATH: cannot open") and reads it
// as its document; results and baselines must say which they are ("kind"), and a schema_version newer than
// kSchemaVersion is refused.
TrialRecord read_trial_record(const std::string& path);
ResultsFile read_results(const std::string& path);
Baseline read_baseline(const std::string& path);
// The same for a document already parsed from `path`.
ResultsFile results_from_json(const nlohmann::json& j, const std::string& path);
Baseline baseline_from_json(const nlohmann::json& j, const std::string& path);
HistoryFile read_history_file(const std::string& path);
// journal.jsonl, skipping lines that do not parse (a line cut short by a kill: its trial runs again).
std::vector<JournalEntry> read_journal(const std::string& path);
// Readies journal.jsonl for appending after an interruption, so that no append can glue onto a line cut
// short. A last line without its newline is either a whole entry (killed just before the newline: the
// newline is added) or torn: its bytes are appended to PATH.torn, for the record, and cut off the journal.
// Returns the torn bytes ("" when there were none). InputError naming the file when it cannot be repaired.
std::string repair_journal(const std::string& path);

// The document as a file's text: one line of compact JSON (journal lines, a suite child's record) when
// indent < 0, else indented; a newline at the end. Strings holding invalid UTF-8 (a message quoting half of
// a multi-byte character) are written with U+FFFD in place of each invalid byte instead of throwing, so a
// record is never lost to its text. Every JSON file the harness writes goes through here.
std::string json_text(const nlohmann::json& j, int indent);

}  // namespace growbench
