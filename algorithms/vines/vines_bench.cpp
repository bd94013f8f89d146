// Vines grown to completion at several vine resolutions (the seed's Figure 16, left: generation time
// against resolution): on the wall's canvas, and in the UV space of spot. Wall time per complete growth,
// start (attractor placement) and finish (assembling the plant) included; scene and query building
// excluded (the scene benchmarks measure them).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "algorithms/algorithm.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {
namespace {

void grow_vines(benchmark::State& state, const Scene& scene, const SceneQuery& query, const char* space) {
  const auto resolution = state.range(0);
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(1)));
  const AlgorithmEntry& e = find_algorithm("vines");
  Params p = default_params(e);
  p.set("space", space);
  p.set("resolution", std::to_string(resolution));
  std::size_t nodes = 0, steps = 0;
  for (auto _ : state) {
    auto algo = e.make();
    algo->start(scene, query, p, 1);
    steps = 0;
    while (algo->step()) ++steps;
    algo->finish();
    nodes = algo->plant().nodes.size();
    benchmark::DoNotOptimize(nodes);
  }
  state.counters["nodes"] = static_cast<double>(nodes);
  state.counters["steps"] = static_cast<double>(steps);
  state.counters["cells"] = static_cast<double>(resolution * resolution);
}

void BM_VinesWallCanvas(benchmark::State& state) {
  static const Scene scene = load_scene("wall");
  static const SceneQuery query(scene);
  grow_vines(state, scene, query, "canvas");
}

void BM_VinesSpotUv(benchmark::State& state) {
  static const Scene scene = load_scene("mesh:spot");
  static const SceneQuery query(scene);
  grow_vines(state, scene, query, "uv");
}

BENCHMARK(BM_VinesWallCanvas)
    ->ArgNames({"resolution", "threads"})
    ->Args({128, 2})
    ->Args({256, 2})
    ->Args({512, 2})
    ->Args({1000, 1})
    ->Args({1000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_VinesSpotUv)
    ->ArgNames({"resolution", "threads"})
    ->Args({256, 2})
    ->Args({1000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace growbench
