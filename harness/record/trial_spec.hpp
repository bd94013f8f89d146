// What one trial is asked to do: the one shape of a trial, which the command line fills, a suite reads for
// each cell, a suite hands its trial's process, and every record embeds, so that a record says exactly
// what ran. Each setting's range is declared here once; `growbench run`'s options and a suite file's keys
// are both checked against it (harness/record/reflect.hpp).
#pragma once

#include <array>
#include <climits>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "harness/record/fields.hpp"

namespace growbench {

// The layout of plant.glb (harness/output/exporters.hpp writes each).
enum class GlbLayout { Plain, Instanced, Compact };
inline constexpr std::array<std::string_view, 3> kGlbLayoutNames = {"plain", "instanced", "compact"};
constexpr std::span<const std::string_view> enum_names(GlbLayout) {
  return kGlbLayoutNames;
}
inline constexpr GlbLayout kDefaultGlbLayout = GlbLayout::Compact;

inline constexpr int kMaxThreads = 1024;
inline constexpr double kMaxTimeLimitS = 1e9;  // a deadline in nanoseconds stays within 64 bits
// Metres (a mesh scene with size=0: the file's units). Below a micrometre a float voxel size loses the
// precision OpenVDB's transform needs, and no scene's distance field would fit in memory anyway.
inline constexpr double kMinVoxelSize = 1e-6, kMaxVoxelSize = 1e6;
inline constexpr double kMaxBudget = 1e12;

struct TrialSpec {
  std::string algorithm;
  std::string scene;                      // standard name, *.json, or mesh:PATH
  std::vector<std::string> scene_params;  // key=value
  std::vector<std::string> params;        // algorithm key=value (--set)
  std::uint64_t seed = 1;
  std::vector<std::array<double, 3>> seed_at;  // replaces the scene's seeds, each snapped to the surface
  int max_steps = 5000;                        // the step cap for every algorithm
  double time_limit_s = 0.0;                   // 0: none; checked between steps
  int threads = 0;                             // 0: all cores
  double voxel_size = 0.0;                     // 0: automatic (see SceneQueryOptions)
  double band_voxels = 0.0;                    // 0: SceneQueryOptions' default
  int sides = 6;                               // tube sides of the branch mesh
  // Comparable budgets across algorithms: stop once the plant has this many nodes / this much branch
  // length (0: no budget). Checked after every step.
  std::uint64_t budget_nodes = 0;
  double budget_length_m = 0.0;
  bool metrics = true;  // compute the quality metrics (harness/output/metrics.hpp)
  // Growth animation: every this many steps (and after the last) the plant is written to
  // OUT/frames/step_NNNNNN.gbplant for `growbench render`, with the images its decals name as
  // step_NNNNNN.IMAGE (0: no frames). The time this takes is recorded and taken out of the growth
  // phase's wall and CPU time.
  int frame_every = 0;
  // For testing the harness only: "crash" (SIGSEGV), "hang", "oom" (allocate until refused) at the
  // start of growth, "throw" (an internal error), "slow:N". Empty in real use.
  std::string fault;
  std::string leaf_obj;  // a custom organ OBJ for every leaf, flower and bud whose plant names no shape
  // The organ pass after growth (harness/organs/options.hpp), as key=value; empty: the plant as grown.
  std::vector<std::string> organs;
  GlbLayout glb = kDefaultGlbLayout;
  // How to run it rather than what to grow; left out of a record when they are their defaults.
  std::string out_dir;  // empty: measure but write no files
  bool context = true;  // add the run context to the record (suites record it once instead)
  // Leave the trial's big objects (scene, query, plant, mesh) allocated at the end: for a forked suite
  // child that exits right after, freeing them would only add time the kernel spends again at exit.
  bool skip_teardown = false;
  // Plugin files to load before the trial looks up its algorithm: what a trial's own process (a suite's
  // forked or callgrind child, an A/B side) needs to find a plugin algorithm.
  std::vector<std::string> plugins;

  static constexpr std::string_view kSchemaName = "spec";
  static constexpr auto fields() {
    using S = TrialSpec;
    return std::tuple{
        field("algorithm", &S::algorithm).with(kRequiredField).describe("algorithm name (see `growbench list`)"),
        field("scene", &S::scene).with(kRequiredField),
        field("scene_params", &S::scene_params).describe("scene parameters, key=value"),
        field("params", &S::params).describe("algorithm parameters, key=value"),
        field("seed", &S::seed).in(0, static_cast<double>(UINT64_MAX)).describe("random seed"),
        field("seed_at", &S::seed_at).in(-1e9, 1e9).describe("seed positions in metres, each snapped to the surface"),
        field("max_steps", &S::max_steps).in(0, INT_MAX).describe("step cap"),
        field("time_limit_s", &S::time_limit_s)
            .in(0, kMaxTimeLimitS)
            .describe("stop growing after this many seconds (0: none)"),
        field("threads", &S::threads).in(0, kMaxThreads).describe("worker threads (0: all cores)"),
        field("voxel_size", &S::voxel_size)
            .in(kMinVoxelSize, kMaxVoxelSize)
            .with(kZeroOr)
            .describe("distance-field voxel size in metres (0: the scene diagonal / 256)"),
        field("band_voxels", &S::band_voxels)
            .in(1, 64)
            .with(kZeroOr)
            .describe("half-width of the distance field's narrow band in voxels, where collision and clinging "
                      "read exact gradients (0: the default)"),
        field("sides", &S::sides).in(3, 64).describe("tube sides of the branch mesh"),
        field("budget_nodes", &S::budget_nodes).in(0, kMaxBudget).describe("stop at this many nodes (0: none)"),
        field("budget_length_m", &S::budget_length_m)
            .in(0, kMaxBudget)
            .describe("stop at this much branch length in metres (0: none)"),
        field("metrics", &S::metrics).describe("compute the quality metrics"),
        field("frame_every", &S::frame_every).in(0, INT_MAX).describe("keep the plant every K steps (0: never)"),
        field("fault", &S::fault).describe("a fault injected into the trial, for testing the harness"),
        field("leaf_obj", &S::leaf_obj).with(kOmitEmpty).describe("a custom organ OBJ"),
        field("organs", &S::organs).with(kOmitEmpty).describe("the organ pass's options, key=value"),
        field("glb", &S::glb).describe("the layout of plant.glb"),
        field("out_dir", &S::out_dir).with(kOmitEmpty),
        field("context", &S::context).with(kOmitDefault),
        field("skip_teardown", &S::skip_teardown).with(kOmitDefault),
        field("plugins", &S::plugins)
            .with(kOmitEmpty)
            .describe("plugin files loaded before the algorithm is looked up"),
    };
  }
};

}  // namespace growbench
