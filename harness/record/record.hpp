// What the harness writes, declared once: a trial's record (record.json of `growbench run` and of a suite's
// trial), the suite's journal lines and results file (results.json), its baseline, and a history file.
//
// Each struct lists its fields once, in fields() (harness/record/fields.hpp says what a declaration can
// say). Everything else is derived from that list: to_json and from_json, merging a cell's results,
// projecting a cell onto its baseline, the columns of results.csv, and results.schema.json beside this
// file (results_schema(); a test fails while the committed file differs, `make schema` rewrites it). So a
// field is added in one place, plus the code that computes it.
//
// Reading is tolerant of absence and strict about everything else. A field missing from the file reads as
// its default (or as empty, for the std::optional members, whose absence means something: a failed sample
// has no phases), so partial and hand-written files stay readable. A field of the wrong type, outside its
// declared range, or one this harness does not know (a renamed field), is an InputError naming the file and
// the JSON path: "results.json: at trials[3].samples[0].phases.growth.wall_s: expected a number".
//
// Open-ended parts stay JSON: algorithm parameters, metrics by name, sweep values, library versions.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/outcome.hpp"
#include "core/plugin_origin.hpp"
#include "harness/record/fields.hpp"
#include "harness/record/trial_spec.hpp"

namespace growbench {

// The version of every document below. A field is only ever added; renaming or retyping one bumps this,
// and the readers keep reading the older version. reports/report.py reads it from results.schema.json.
inline constexpr int kSchemaVersion = 1;
inline constexpr std::string_view kResultsKind = "growbench-results";
inline constexpr std::string_view kBaselineKind = "growbench-baseline";
inline constexpr std::string_view kHistoryKind = "growbench-history";

// The values some string fields take.
inline constexpr std::array<std::string_view, 5> kStoppedBy = {"finished", "max_steps", "time_limit", "budget_nodes",
                                                               "budget_length"};
inline constexpr std::array<std::string_view, 3> kDirtyValues = {"true", "false", "unknown"};
inline constexpr std::array<std::string_view, 2> kModes = {"timing", "instructions"};
inline constexpr std::array<std::string_view, 4> kRenderStatuses = {"ok", "failed", "timeout", "no_povray"};
inline constexpr std::array<std::string_view, 3> kAnimationStatuses = {"ok", "failed", "no_ffmpeg"};
inline constexpr std::array<std::string_view, 2> kCameraUsed = {"scene", "fitted"};
inline constexpr std::array<std::string_view, 2> kCameraAsked = {"auto", "scene"};
inline constexpr std::array<std::string_view, 2> kBackdrops = {"scene", "studio"};
// A trial's status in a suite (core/outcome.hpp), and a cell's, which is "pending" before it ran.
inline constexpr auto kSampleStatuses = kTrialStatuses;
inline constexpr auto kCellStatuses = [] {
  std::array<std::string_view, kTrialStatuses.size() + 1> a{"pending"};
  for (std::size_t i = 0; i < kTrialStatuses.size(); ++i) a[i + 1] = kTrialStatuses[i];
  return a;
}();

// A record's fields, and its name in results.schema.json's $defs, for structs declared elsewhere.
constexpr auto record_fields(std::type_identity<PluginOrigin>) {
  using P = PluginOrigin;
  return std::tuple{field("name", &P::name).with(kRequiredField), field("path", &P::path).with(kRequiredField),
                    field("hash", &P::hash).with(kRequiredField),
                    field("abi_version", &P::abi_version).with(kRequiredField).in(1, UINT32_MAX),
                    field("version", &P::version)};
}
constexpr std::string_view record_schema_name(std::type_identity<PluginOrigin>) {
  return "plugin";
}

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

  static constexpr std::string_view kSchemaName = "phase";
  static constexpr auto fields() {
    using P = PhaseMeasures;
    return std::tuple{field("wall_s", &P::wall_s),
                      field("cpu_s", &P::cpu_s),
                      field("peak_rss_bytes", &P::peak_rss_bytes),
                      field("peak_rss_reset", &P::peak_rss_reset),
                      field("alloc_count", &P::alloc_count),
                      field("alloc_bytes", &P::alloc_bytes),
                      field("bvh_s", &P::bvh_s),
                      field("sdf_s", &P::sdf_s),
                      field("sdf_active_voxels", &P::sdf_active_voxels),
                      field("voxel_size_m", &P::voxel_size_m),
                      field("frame_capture_wall_s", &P::frame_capture_wall_s),
                      field("frame_capture_cpu_s", &P::frame_capture_cpu_s)};
  }
};

// A trial's phases, each absent when it did not run (metrics with metrics off; all of them in a hand-written
// sample).
using Phases = PhaseMap<PhaseMeasures>;

struct Counts {
  std::uint64_t nodes = 0, segments = 0, leaves = 0, organs = 0, polygons = 0, mesh_vertices = 0, mesh_triangles = 0;
  friend bool operator==(const Counts&, const Counts&) = default;

  static constexpr std::string_view kSchemaName = "counts";
  static constexpr auto fields() {
    using C = Counts;
    return std::tuple{field("nodes", &C::nodes),
                      field("segments", &C::segments),
                      field("leaves", &C::leaves),
                      field("organs", &C::organs),
                      field("polygons", &C::polygons),
                      field("mesh_vertices", &C::mesh_vertices),
                      field("mesh_triangles", &C::mesh_triangles)};
  }
};

// Bytes written per output format; empty when the trial wrote no files.
struct OutputBytes {
  std::optional<std::uint64_t> obj, ply, glb, skeleton_obj, skeleton_ply;
  // The bytes plant.glb would have in the plain layout (docs/metrics.md), computed without writing it.
  std::optional<std::uint64_t> glb_plain;
  // The files only the algorithm makes (GrowthAlgorithm::write_outputs), by name; absent when none.
  std::map<std::string, std::uint64_t> algorithm_files;

  static constexpr std::string_view kSchemaName = "output_bytes";
  static constexpr auto fields() {
    using O = OutputBytes;
    return std::tuple{
        field("obj", &O::obj),
        field("ply", &O::ply),
        field("glb", &O::glb),
        field("glb_plain", &O::glb_plain),
        field("skeleton_obj", &O::skeleton_obj),
        field("skeleton_ply", &O::skeleton_ply),
        field("algorithm_files", &O::algorithm_files)
            .with(kOmitEmpty)
            .refine(R"({"minProperties": 1, "propertyNames": {"minLength": 1}})")
            .describe("bytes of each file only the algorithm makes (GrowthAlgorithm::write_outputs), by file "
                      "name; absent when none")};
  }
};

// The growth curve: a bounded number of points, thinned by doubling `every` (kCurveCap in harness/run/trial.cpp).
struct Curve {
  int every = 1;
  std::vector<int> step;
  std::vector<std::uint64_t> nodes, organs;
  std::vector<double> wall_s;

  static constexpr std::string_view kSchemaName = "curve";
  static constexpr auto fields() {
    using C = Curve;
    return std::tuple{field("every", &C::every).in(1, INT_MAX), field("step", &C::step).in(0, INT_MAX),
                      field("nodes", &C::nodes), field("organs", &C::organs), field("wall_s", &C::wall_s)};
  }
};

// The scene as the trial loaded it.
struct SceneInfo {
  std::string spec, name, hash;
  std::uint64_t triangles = 0, seeds = 0;
  std::vector<std::string> params;  // key=value

  static constexpr std::string_view kSchemaName = "scene";
  static constexpr auto fields() {
    using S = SceneInfo;
    return std::tuple{
        field("spec", &S::spec),           field("name", &S::name),   field("hash", &S::hash).refine(kHashSchema),
        field("triangles", &S::triangles), field("seeds", &S::seeds), field("params", &S::params)};
  }
};

struct FramesInfo {
  int every = 0, count = 0;
  std::string dir;  // relative to the trial's directory

  static constexpr std::string_view kSchemaName = "frames";
  static constexpr auto fields() {
    using F = FramesInfo;
    return std::tuple{field("every", &F::every), field("count", &F::count), field("dir", &F::dir)};
  }
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
  // The machine's state, where it can be read: the load averages (1, 5, 15 minutes) when the run began and
  // when it ended, the first core's clock and frequency governor. A loaded machine's timings are not a quiet
  // one's, and `summary` and the report say so.
  std::optional<std::array<double, 3>> load_average_start, load_average_end;
  std::optional<double> cpu_mhz;
  std::optional<std::string> cpu_governor;

  static constexpr std::string_view kSchemaName = "context";
  static constexpr auto fields() {
    using R = RunContext;
    return std::tuple{
        field("growbench_commit", &R::growbench_commit),
        field("dirty", &R::dirty).one_of(kDirtyValues),
        field("commit_time", &R::commit_time).with(kNullable),
        field("configured_commit", &R::configured_commit),
        field("build_type", &R::build_type),
        field("compiler", &R::compiler),
        field("cxx_flags", &R::cxx_flags),
        field("binary_hash", &R::binary_hash),
        field("cpu_model", &R::cpu_model),
        field("hardware_threads", &R::hardware_threads),
        field("date", &R::date),
        field("alloc_counting", &R::alloc_counting),
        field("dependencies", &R::dependencies).refine(R"({"additionalProperties": {"type": ["string", "number"]}})"),
        field("suite_file_hash", &R::suite_file_hash).refine(kHashSchema),
        field("parent_threads_at_fork", &R::parent_threads_at_fork),
        field("mixed_machines", &R::mixed_machines),
        field("plugins", &R::plugins).with(kOmitEmpty),
        field("load_average_start", &R::load_average_start).in(0, kNoBound),
        field("load_average_end", &R::load_average_end).in(0, kNoBound),
        field("cpu_mhz", &R::cpu_mhz).in(0, kNoBound),
        field("cpu_governor", &R::cpu_governor)};
  }
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
  // The share of the plant's sampled points inside this camera's frame, and visible in it past the scene
  // (ray casts against the scene meshes); the share of the image's pixels that show the plant.
  std::optional<double> in_frame_share, visible_share, plant_pixel_share;
  std::optional<bool> dof;
  // The least width on screen, in pixels, branches were drawn with (RenderOptions::min_branch_px).
  std::optional<double> min_branch_px;

  static constexpr std::string_view kSchemaName = "render";
  static constexpr auto fields() {
    using R = RenderRecord;
    return std::tuple{field("status", &R::status).one_of(kRenderStatuses),
                      field("message", &R::message),
                      field("warnings", &R::warnings),
                      field("png", &R::png),
                      field("pov", &R::pov),
                      field("log", &R::log),
                      field("width", &R::width),
                      field("height", &R::height),
                      field("pov_bytes", &R::pov_bytes),
                      field("write_s", &R::write_s),
                      field("wall_s", &R::wall_s),
                      field("cpu_s", &R::cpu_s),
                      field("quality", &R::quality),
                      field("branches", &R::branches),
                      field("threads", &R::threads),
                      field("camera", &R::camera).one_of(kCameraUsed),
                      field("scene_extent", &R::scene_extent).in(0, kNoBound),
                      field("in_frame_share", &R::in_frame_share).in(0, 1),
                      field("visible_share", &R::visible_share).in(0, 1),
                      field("plant_pixel_share", &R::plant_pixel_share).in(0, 1),
                      field("backdrop", &R::backdrop).one_of(kBackdrops),
                      field("dof", &R::dof),
                      field("min_branch_px", &R::min_branch_px).in(0, kNoBound)};
  }
};

// The growth animation made from a trial's frames, or a turntable (the camera orbiting the plant).
struct AnimationRecord {
  std::string status;  // ok | failed | no_ffmpeg
  std::uint64_t frames = 0;
  std::optional<std::string> frame_pattern, message, file;
  std::optional<std::uint64_t> bytes;

  static constexpr std::string_view kSchemaName = "animation";
  static constexpr auto fields() {
    using A = AnimationRecord;
    return std::tuple{field("status", &A::status).one_of(kAnimationStatuses),
                      field("frames", &A::frames),
                      field("frame_pattern", &A::frame_pattern),
                      field("message", &A::message),
                      field("file", &A::file),
                      field("bytes", &A::bytes)};
  }
};

// What `growbench render` made of a trial: written into the trial's record, or its cell.
struct Media {
  std::optional<RenderRecord> render;
  std::optional<AnimationRecord> animation;
  std::optional<AnimationRecord> turntable;  // growbench render --turntable N: turntable/frame_NNNN.png

  static constexpr std::string_view kSchemaName = "media";
  static constexpr auto fields() {
    return std::tuple{field("render", &Media::render).with(kNoCsv), field("animation", &Media::animation).with(kNoCsv),
                      field("turntable", &Media::turntable).with(kNoCsv)};
  }
};

// The organ pass after growth (harness/organs/): its settings and what placement did.
// What the organ pass did with the organs of one kind, or with all of them.
struct OrganCounts {
  std::uint64_t placed = 0, fallen_back = 0, dropped = 0;  // as grown; turned, smaller or as a fallback; left out
  friend bool operator==(const OrganCounts&, const OrganCounts&) = default;

  static constexpr std::string_view kSchemaName = "organ_counts";
  static constexpr auto fields() {
    using O = OrganCounts;
    return std::tuple{field("placed", &O::placed), field("fallen_back", &O::fallen_back),
                      field("dropped", &O::dropped)};
  }
};

struct OrganPassRecord {
  nlohmann::json options = nlohmann::json::object();  // every organ option with its effective value
  std::uint64_t placed = 0, fallen_back = 0, dropped = 0;
  std::map<std::string, OrganCounts> by_kind;  // by organ kind as grown (leaf, flower, ...): the kinds the plant has

  static constexpr std::string_view kSchemaName = "organ_pass";
  static constexpr auto fields() {
    using O = OrganPassRecord;
    return std::tuple{field("options", &O::options).with(kNoCsv), field("placed", &O::placed),
                      field("fallen_back", &O::fallen_back), field("dropped", &O::dropped),
                      field("by_kind", &O::by_kind).with(kNoCsv)};
  }
};

// Whether the plant a trial grew is one its numbers may stand for (harness/output/validity.hpp; the checks
// and their thresholds are in docs/metrics.md): valid, degenerate (a plant that failed: flat, inside a solid,
// never reached its surface), or not_applicable (the algorithm cannot grow on this scene, by its own word).
// Only valid plants enter comparisons across cells: medians over seeds, fits, figures.
inline constexpr std::array<std::string_view, 3> kVerdicts = {"valid", "degenerate", "not_applicable"};
struct Verdict {
  std::string status = "valid";
  std::vector<std::string> reasons;  // each failed check, or why the scene is not applicable

  [[nodiscard]] bool valid() const { return status == "valid"; }
  static constexpr std::string_view kSchemaName = "verdict";
  static constexpr auto fields() {
    return std::tuple{field("status", &Verdict::status).one_of(kVerdicts),
                      field("reasons", &Verdict::reasons).with(kOmitEmpty)};
  }
};

// A file the algorithm read its input from (GrowthAlgorithm::input_files), with its content's hash, so that a
// result says which grammar or point cloud it grew from, not only where it lay.
struct InputFile {
  std::string param;  // the parameter that named it
  std::string path;   // as the algorithm opened it
  std::string hash;   // XXH3 (64 bits) of its content, 16 hex digits
  friend bool operator==(const InputFile&, const InputFile&) = default;

  static constexpr std::string_view kSchemaName = "input_file";
  static constexpr auto fields() {
    using F = InputFile;
    return std::tuple{field("param", &F::param), field("path", &F::path), field("hash", &F::hash).refine(kHashSchema)};
  }
};

// What a trial grew and what the plant measures: the same for every successful repetition of a cell, so a
// suite keeps it once per cell. A trial's record and a cell's results both hold it, field for field.
struct TrialResults {
  std::string geometry_hash;
  Counts counts;
  OutputBytes output_bytes;
  std::optional<nlohmann::json> metrics;  // by name (harness/output/metrics.hpp); absent with metrics off
  double total_length_m = 0.0;
  int steps = 0;
  std::string stopped_by = "finished";  // kStoppedBy
  Curve curve;
  nlohmann::json params = nlohmann::json::object();  // the algorithm's effective parameters by name
  std::vector<InputFile> inputs;                     // the files it read them from, when any
  std::vector<std::string> warnings;                 // what in its input parsed but likely was not meant
  std::map<std::string, double> algorithm_stats;
  std::uint64_t threads = 0;              // the threads it ran with
  std::optional<OrganPassRecord> organs;  // only when the pass ran (an organ option was given)
  std::optional<Verdict> verdict;         // absent in files written before plants were judged

  static constexpr std::string_view kSchemaName = "trial_results";
  static constexpr auto fields() {
    using T = TrialResults;
    return std::tuple{field("geometry_hash", &T::geometry_hash).refine(kHashSchema),
                      field("counts", &T::counts),
                      field("output_bytes", &T::output_bytes),
                      field("metrics", &T::metrics),
                      field("total_length_m", &T::total_length_m),
                      field("steps", &T::steps).in(0, INT_MAX),
                      field("stopped_by", &T::stopped_by).one_of(kStoppedBy),
                      field("curve", &T::curve).with(kNoCsv),
                      field("params", &T::params).with(kNoCsv),
                      field("inputs", &T::inputs).with(kNoCsv),
                      field("warnings", &T::warnings).with(kNoCsv | kOmitEmpty),
                      field("algorithm_stats", &T::algorithm_stats),
                      field("threads", &T::threads),
                      field("organs", &T::organs),
                      field("verdict", &T::verdict)};
  }
};

// record.json: one trial (run_trial in harness/run/trial.hpp).
struct TrialRecord {
  int schema_version = kSchemaVersion;
  std::string status = "ok";
  std::string algorithm;
  std::uint64_t seed = 1;
  int max_steps = 0;
  TrialSpec spec;  // everything the trial was asked to do
  Phases phases;
  SceneInfo scene;
  std::optional<std::string> leaf_obj;
  std::optional<FramesInfo> frames;
  std::optional<std::uint64_t> snapshot_bytes;  // plant.gbplant, when the trial wrote files
  TrialResults results;
  std::uint64_t peak_rss_bytes = 0;   // the whole process's, never reset
  std::optional<RunContext> context;  // absent in a suite's trials (the suite records it once)
  Media media;                        // added by growbench render

  static constexpr std::string_view kSchemaName = "trial_record";
  static constexpr auto fields() {
    using T = TrialRecord;
    return std::tuple{field("schema_version", &T::schema_version).with(kConstDefault),
                      field("status", &T::status).with(kConstDefault),
                      field("algorithm", &T::algorithm),
                      field("seed", &T::seed),
                      field("max_steps", &T::max_steps).in(0, INT_MAX),
                      field("spec", &T::spec),
                      field("phases", &T::phases),
                      field("scene", &T::scene),
                      field("leaf_obj", &T::leaf_obj),
                      field("frames", &T::frames),
                      field("snapshot_bytes", &T::snapshot_bytes),
                      field("results", &T::results).with(kInline),
                      field("peak_rss_bytes", &T::peak_rss_bytes),
                      field("context", &T::context),
                      field("media", &T::media).with(kInline)};
  }
};

// ---------------------------------------------------------------- a suite

using InstructionCounts = PhaseMap<std::uint64_t>;  // instructions per phase (callgrind)

struct AllocCount {
  std::uint64_t count = 0, bytes = 0;
  friend bool operator==(const AllocCount&, const AllocCount&) = default;

  static constexpr std::string_view kSchemaName = "alloc_count";
  static constexpr auto fields() {
    return std::tuple{field("count", &AllocCount::count), field("bytes", &AllocCount::bytes)};
  }
};
using AllocByPhase = PhaseMap<AllocCount>;

// One repetition of a cell (a journal line's "sample", an entry of a cell's "samples").
struct SuiteSample {
  int repetition = 0;
  std::string status;  // kSampleStatuses
  std::optional<std::string> message;
  double child_wall_s = 0.0, child_user_s = 0.0, child_system_s = 0.0;
  std::uint64_t child_max_rss_bytes = 0;
  std::optional<Phases> phases;  // ok samples
  std::optional<int> steps;
  // Ok samples: the plant this repetition grew, compared with the cell's first to catch nondeterminism.
  std::optional<std::string> geometry_hash;
  std::optional<InstructionCounts> instructions;  // --instructions
  // Where the time outside the phases went (timing mode; harness/suite/suite.cpp).
  std::optional<double> outside_phases_s, launch_s, launch_fork_s, child_bookkeeping_s, teardown_s, parent_s,
      harness_overhead_s;

  static constexpr std::string_view kSchemaName = "sample";
  static constexpr auto fields() {
    using S = SuiteSample;
    return std::tuple{field("repetition", &S::repetition).in(0, INT_MAX),
                      field("status", &S::status).one_of(kSampleStatuses),
                      field("message", &S::message),
                      field("child_wall_s", &S::child_wall_s),
                      field("child_user_s", &S::child_user_s),
                      field("child_system_s", &S::child_system_s),
                      field("child_max_rss_bytes", &S::child_max_rss_bytes),
                      field("phases", &S::phases).with(kWhenOk),
                      field("steps", &S::steps).with(kWhenOk).in(0, INT_MAX),
                      field("geometry_hash", &S::geometry_hash).refine(kHashSchema),
                      field("instructions", &S::instructions),
                      field("outside_phases_s", &S::outside_phases_s),
                      field("launch_s", &S::launch_s),
                      field("launch_fork_s", &S::launch_fork_s),
                      field("child_bookkeeping_s", &S::child_bookkeeping_s),
                      field("teardown_s", &S::teardown_s),
                      field("parent_s", &S::parent_s),
                      field("harness_overhead_s", &S::harness_overhead_s)};
  }
};

// A cell's results, from its first successful repetition: what the plant is, and what the suite adds.
struct CellResults {
  std::optional<TrialResults> plant;
  std::optional<std::string> scene_hash;
  std::optional<AllocByPhase> alloc;
  std::optional<InstructionCounts> instructions;

  static constexpr std::string_view kSchemaName = "cell_results";
  static constexpr auto fields() {
    using C = CellResults;
    return std::tuple{field("plant", &C::plant).with(kInline | kWhenOk),
                      field("scene_hash", &C::scene_hash).with(kWhenOk).refine(kHashSchema),
                      field("alloc", &C::alloc).with(kWhenOk), field("instructions", &C::instructions)};
  }
};

// A median and its distribution-free 95% interval (median_interval in harness/stats/stats.hpp).
struct MedianSummary {
  std::uint64_t n = 0;  // samples
  double median = 0.0, lo = 0.0, hi = 0.0;
  bool exact = false;  // false: fewer than 6 samples, [lo, hi] is the full range

  static constexpr std::string_view kSchemaName = "median";
  static constexpr auto fields() {
    using M = MedianSummary;
    return std::tuple{field("n", &M::n).in(1, kNoBound), field("median", &M::median), field("lo", &M::lo),
                      field("hi", &M::hi), field("exact", &M::exact)};
  }
  static constexpr std::string_view kSchemaDoc =
      "A median and its distribution-free 95% interval (harness/stats/stats.hpp median_interval); exact is false "
      "below 6 samples, where [lo, hi] is the full range.";
};

// Statistics of a cell's ok repetitions, computed by the suite so that reports do not compute them again.
struct CellSummary {
  std::optional<MedianSummary> growth_s;  // the growth phase's wall time

  static constexpr std::string_view kSchemaName = "cell_summary";
  static constexpr auto fields() { return std::tuple{field("growth_s", &CellSummary::growth_s)}; }
};

// A line of journal.jsonl: one finished repetition, durable before the next trial starts.
struct JournalEntry {
  std::string id;
  SuiteSample sample;
  std::optional<CellResults> cell;  // the cell's results, with its first successful repetition; else null

  static constexpr std::string_view kSchemaName = "journal_entry";
  static constexpr auto fields() {
    using J = JournalEntry;
    return std::tuple{field("id", &J::id).with(kRequiredField), field("sample", &J::sample),
                      field("cell", &J::cell).with(kNullable)};
  }
};

// An entry of results.json "trials": one cell of the suite's matrix with its repetitions.
struct SuiteCell {
  std::string id, label, algorithm, scene, scene_spec;
  std::uint64_t seed = 1;
  nlohmann::json sweep = nlohmann::json::object();  // the swept parameters' values
  TrialSpec spec;
  std::string status = "pending";  // ok, or the last failed repetition's status
  std::optional<std::string> message;
  std::optional<bool> nondeterministic;  // two repetitions grew different plants
  std::vector<SuiteSample> samples;
  CellResults results;  // written into the cell's own object
  std::optional<CellSummary> summary;
  Media media;

  static constexpr std::string_view kSchemaName = "cell";
  static constexpr auto fields() {
    using C = SuiteCell;
    return std::tuple{field("id", &C::id).with(kRequiredField),
                      field("label", &C::label),
                      field("algorithm", &C::algorithm),
                      field("scene", &C::scene),
                      field("scene_spec", &C::scene_spec),
                      field("seed", &C::seed),
                      field("sweep", &C::sweep),
                      field("spec", &C::spec).with(kNoCsv),
                      field("status", &C::status).one_of(kCellStatuses),
                      field("message", &C::message),
                      field("nondeterministic", &C::nondeterministic),
                      field("samples", &C::samples),
                      field("results", &C::results).with(kInline),
                      field("summary", &C::summary).with(kNoCsv),
                      field("media", &C::media).with(kInline)};
  }
};

struct SuiteInfo {
  std::string name, file, description;

  static constexpr std::string_view kSchemaName = "suite";
  static constexpr auto fields() {
    return std::tuple{field("name", &SuiteInfo::name), field("file", &SuiteInfo::file),
                      field("description", &SuiteInfo::description)};
  }
};

struct ShardInfo {
  int index = 0, count = 1;

  static constexpr std::string_view kSchemaName = "shard";
  static constexpr auto fields() {
    return std::tuple{field("index", &ShardInfo::index).in(0, INT_MAX),
                      field("count", &ShardInfo::count).in(1, INT_MAX)};
  }
};

// A merged file's record of one shard.
struct ShardRecord {
  int index = 0;
  std::string file;
  RunContext context;

  static constexpr std::string_view kSchemaName = "shard_record";
  static constexpr auto fields() {
    return std::tuple{field("index", &ShardRecord::index).in(0, INT_MAX), field("file", &ShardRecord::file),
                      field("context", &ShardRecord::context)};
  }
};

// The renders of a results directory (growbench render).
struct RenderSummary {
  std::string quality, branches, povray;
  int width = 0, height = 0, jobs = 0, threads_per_render = 0;
  std::uint64_t renders = 0, ok = 0, failed = 0, warnings = 0, skipped_without_snapshot = 0;
  double povray_s = 0.0, wall_s = 0.0;
  std::optional<std::string> grid, grid_error;
  std::optional<std::map<std::string, std::string>> grid_per_scene;  // scene -> image
  // The grid split into pages of at most kGridPageScenes scenes, each readable at a page's width; beside
  // each image (and each per-scene grid) IMAGE.map.json says which trial each cell shows and where.
  std::optional<std::vector<std::string>> grid_pages;
  std::optional<std::string> camera, backdrop;  // as asked: auto | scene, scene | studio
  std::optional<bool> dof;
  std::optional<std::uint64_t> turntable;  // frames per trial

  static constexpr std::string_view kSchemaName = "render_summary";
  static constexpr auto fields() {
    using R = RenderSummary;
    return std::tuple{field("quality", &R::quality),
                      field("branches", &R::branches),
                      field("width", &R::width),
                      field("height", &R::height),
                      field("povray", &R::povray),
                      field("jobs", &R::jobs),
                      field("threads_per_render", &R::threads_per_render),
                      field("renders", &R::renders),
                      field("ok", &R::ok),
                      field("failed", &R::failed),
                      field("warnings", &R::warnings),
                      field("skipped_without_snapshot", &R::skipped_without_snapshot),
                      field("povray_s", &R::povray_s),
                      field("wall_s", &R::wall_s),
                      field("grid", &R::grid),
                      field("grid_error", &R::grid_error),
                      field("grid_per_scene", &R::grid_per_scene),
                      field("grid_pages", &R::grid_pages),
                      field("camera", &R::camera).one_of(kCameraAsked),
                      field("backdrop", &R::backdrop).one_of(kBackdrops),
                      field("dof", &R::dof),
                      field("turntable", &R::turntable)};
  }
};

// Growth time over the seeds of one algorithm entry (and sweep point) on one scene: the rows of the
// report's table.
struct PooledSummary {
  std::string label, scene;
  nlohmann::json sweep = nlohmann::json::object();
  std::vector<std::string> cells;  // the ok cells pooled
  MedianSummary growth_s;

  static constexpr std::string_view kSchemaName = "pooled_summary";
  static constexpr auto fields() {
    using P = PooledSummary;
    return std::tuple{field("label", &P::label), field("scene", &P::scene), field("sweep", &P::sweep),
                      field("cells", &P::cells), field("growth_s", &P::growth_s)};
  }
};

struct ResultsSummary {
  std::vector<PooledSummary> growth_s_over_seeds;

  static constexpr std::string_view kSchemaName = "results_summary";
  static constexpr auto fields() {
    return std::tuple{field("growth_s_over_seeds", &ResultsSummary::growth_s_over_seeds)
                          .describe("Per algorithm entry (and sweep point) and scene: the growth time of every ok "
                                    "repetition of its ok cells (one per seed) whose plants are valid, pooled.")};
  }
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
  std::optional<std::map<std::string, std::string>> scenes;  // scene content hash -> its scene.glb

  static constexpr std::string_view kSchemaName = "results";
  static constexpr auto fields() {
    using R = ResultsFile;
    return std::tuple{field("schema_version", &R::schema_version).with(kConstDefault),
                      field("kind", &R::kind).with(kRequiredField | kConstDefault),
                      field("mode", &R::mode).one_of(kModes),
                      field("suite", &R::suite),
                      field("suite_hash", &R::suite_hash).refine(kHashSchema),
                      field("repetitions", &R::repetitions).in(1, INT_MAX),
                      field("shard", &R::shard),
                      field("context", &R::context),
                      field("trials", &R::trials).with(kRequiredField),
                      field("shards", &R::shards),
                      field("renders", &R::renders),
                      field("summary", &R::summary),
                      field("scenes", &R::scenes)
                          .describe("Each scene the trials grew on (by its content hash, the trials' scene_hash): its "
                                    "meshes, light and camera as a .glb, relative to this file (the report's 3D "
                                    "views show each plant on it).")};
  }
};

// ---------------------------------------------------------------- the gate and the history

struct BaselineContext {
  std::string growbench_commit, dirty, compiler, cxx_flags, build_type;
  nlohmann::json dependencies = nlohmann::json::object();
  std::vector<PluginOrigin> plugins;  // so that compare can say a plugin is another build

  static constexpr std::string_view kSchemaName = "baseline_context";
  static constexpr auto fields() {
    using B = BaselineContext;
    return std::tuple{
        field("growbench_commit", &B::growbench_commit),
        field("dirty", &B::dirty).one_of(kDirtyValues),
        field("compiler", &B::compiler),
        field("cxx_flags", &B::cxx_flags),
        field("build_type", &B::build_type),
        field("dependencies", &B::dependencies).refine(R"({"additionalProperties": {"type": ["string", "number"]}})"),
        field("plugins", &B::plugins).with(kOmitEmpty)};
  }
};

// A cell as a baseline keeps it: what the regression gate compares, no timings. Each field is the cell's
// field of the same key (project() in harness/record/reflect.hpp copies them).
struct BaselineCell {
  std::string id, label, algorithm, scene;
  std::uint64_t seed = 1;
  std::string status;
  std::optional<std::uint64_t> threads;
  std::optional<std::string> geometry_hash;
  std::optional<Counts> counts;
  std::optional<nlohmann::json> metrics;
  std::optional<Verdict> verdict;
  std::optional<OutputBytes> output_bytes;
  std::optional<AllocByPhase> alloc;
  std::optional<InstructionCounts> instructions;

  static constexpr std::string_view kSchemaName = "baseline_cell";
  static constexpr auto fields() {
    using B = BaselineCell;
    return std::tuple{field("id", &B::id).with(kRequiredField),
                      field("label", &B::label),
                      field("algorithm", &B::algorithm),
                      field("scene", &B::scene),
                      field("seed", &B::seed),
                      field("status", &B::status).one_of(kCellStatuses),
                      field("threads", &B::threads),
                      field("geometry_hash", &B::geometry_hash).refine(kHashSchema),
                      field("counts", &B::counts),
                      field("metrics", &B::metrics),
                      field("verdict", &B::verdict),
                      field("output_bytes", &B::output_bytes),
                      field("alloc", &B::alloc),
                      field("instructions", &B::instructions)};
  }
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

  static constexpr std::string_view kSchemaName = "baseline";
  static constexpr auto fields() {
    using B = Baseline;
    return std::tuple{field("schema_version", &B::schema_version).with(kConstDefault),
                      field("kind", &B::kind).with(kRequiredField | kConstDefault),
                      field("mode", &B::mode).one_of(kModes),
                      field("suite", &B::suite),
                      field("suite_hash", &B::suite_hash).refine(kHashSchema),
                      field("context", &B::context),
                      field("trials", &B::trials).with(kRequiredField)};
  }
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

  static constexpr std::string_view kSchemaName = "history_cell";
  static constexpr auto fields() {
    using H = HistoryCell;
    return std::tuple{field("status", &H::status),
                      field("geometry_hash", &H::geometry_hash),
                      field("nodes", &H::nodes),
                      field("total_wall_s", &H::total_wall_s),
                      field("total_wall_s_n", &H::total_wall_s_n),
                      field("growth_wall_s", &H::growth_wall_s),
                      field("growth_wall_s_n", &H::growth_wall_s_n),
                      field("growth_cpu_s", &H::growth_cpu_s),
                      field("growth_cpu_s_n", &H::growth_cpu_s_n),
                      field("growth_peak_rss_bytes", &H::growth_peak_rss_bytes),
                      field("growth_peak_rss_bytes_n", &H::growth_peak_rss_bytes_n),
                      field("instructions", &H::instructions)};
  }
};

struct HistoryRun {
  std::string date, mode, dirty, build_type;
  std::map<std::string, HistoryCell> cells;  // by cell id

  static constexpr std::string_view kSchemaName = "history_run";
  static constexpr auto fields() {
    using H = HistoryRun;
    return std::tuple{field("date", &H::date), field("mode", &H::mode), field("dirty", &H::dirty),
                      field("build_type", &H::build_type), field("cells", &H::cells)};
  }
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

  static constexpr std::string_view kSchemaName = "history";
  static constexpr auto fields() {
    using H = HistoryFile;
    return std::tuple{field("kind", &H::kind).with(kRequiredField | kConstDefault),
                      field("schema_version", &H::schema_version).with(kConstDefault),
                      field("commit", &H::commit),
                      field("commit_time", &H::commit_time).with(kNullable),
                      field("machine", &H::machine),
                      field("cpu_model", &H::cpu_model),
                      field("hardware_threads", &H::hardware_threads),
                      field("suite", &H::suite),
                      field("runs", &H::runs)};
  }
};

// ---------------------------------------------------------------- serialising

// Every struct above (and TrialSpec, PluginOrigin) as JSON, and back: T from JSON read from `source` (a file
// name, for errors). Throws InputError "SOURCE: at PATH: WHAT" for a value of the wrong type, outside its
// range, or an unknown field.
template <Declared T>
nlohmann::json to_json(const T& v);
template <Declared T>
T from_json(const nlohmann::json& j, const std::string& source);
// Phases, allocations and instructions by phase.
template <class T>
nlohmann::json to_json(const PhaseMap<T>& v);

// Reads `j` into the TrialSpec field declared under `key`, with its type, range and names: how a suite file's
// settings are checked as the command line's are. InputError "SOURCE: at PATH: WHAT".
void read_spec_field(TrialSpec& spec, std::string_view key, const nlohmann::json& j, const std::string& source,
                     const std::string& path);

// InputError "the trial spec: KEY: WHAT" for the first setting outside its declared range: a spec made in
// code is held to what the command line and suite files are.
void check_trial_spec(const TrialSpec& spec);

// results.schema.json as this binary declares it (its $defs also describe record.json, the baseline, the
// journal and history files).
nlohmann::json results_schema();

// The column names of results.csv, and its rows: one per repetition, the cell's fields and then the
// sample's, each a dotted JSON path ("counts.nodes", "sample.phases.growth.wall_s").
std::string results_csv(const ResultsFile& results);

// The cell as its baseline keeps it.
BaselineCell baseline_cell_of(const SuiteCell& cell);

// Every present field of `from` into `to` (the results of a cell's first successful repetition).
void take_present(CellResults& to, const CellResults& from);

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
