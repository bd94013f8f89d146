// Space colonization grown to completion on the envelope scene (a free-growing tree filling an
// ellipsoidal crown), at several attraction-point counts and thread counts. Wall time per complete
// growth (scene and query building excluded: they are measured by the scene benchmarks).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "algorithms/algorithm.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {
namespace {

void BM_SpacecolEnvelope(benchmark::State& state) {
  const auto points = state.range(0);
  const auto threads = static_cast<std::size_t>(state.range(1));
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  static const Scene scene = load_scene("envelope");
  static const SceneQuery query(scene);
  const AlgorithmEntry& e = find_algorithm("spacecol");
  Params p = default_params(e);
  p.set("point_count", std::to_string(points));
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
  state.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_SpacecolEnvelope)
    ->ArgNames({"points", "threads"})
    ->Args({10000, 1})
    ->Args({10000, 2})
    ->Args({100000, 1})
    ->Args({100000, 2})
    ->Args({1000000, 1})
    ->Args({1000000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace growbench
