// Luft ivy: growth rate per core on the wall and on the Stanford bunny, the cost of a node against one
// bounded closest-point query plus one ray at the same positions, bytes per node, and a scaling run
// over two decades of nodes. Growth only (scene, BVH and distance field are built once, outside).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cmath>

#include "algorithms/ivy/ivy.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {
namespace {

struct IvyScene {
  Scene scene;
  std::unique_ptr<SceneQuery> query;
  std::unique_ptr<ivy::TriangleTable> table;
};

// The wall scene, or the bunny with a seed on its flank (its lowest vertex sits on a hole's rim).
IvyScene& ivy_scene(int which) {
  static IvyScene scenes[2];
  IvyScene& s = scenes[which];
  if (!s.query) {
    s.scene = which == 0 ? load_scene("wall") : load_scene("mesh:stanford-bunny");
    s.query = std::make_unique<SceneQuery>(s.scene, SceneQueryOptions{.build_sdf = false});
    if (which == 1) s.scene.seeds = {{s.query->closest_point({0.0f, 0.8f, 1.0f}).point, {0, 1, 0}, 0}};
    s.table = std::make_unique<ivy::TriangleTable>(s.scene);
  }
  return s;
}

struct GrowResult {
  std::size_t nodes = 0;
  double seconds = 0.0;
  double bytes_per_node = 0.0;
  std::vector<glm::vec3> positions;
};

// Grows until `budget` nodes (or until growth ends), timing the steps only.
GrowResult grow(IvyScene& s, std::size_t budget, const std::vector<std::string>& sets, bool keep_positions = false) {
  Params p = default_params(find_algorithm("ivy"));
  for (const auto& a : sets) p.set_assignment(a);
  const ivy::Config cfg = ivy::make_config(p, s.scene);
  const auto geometry = ivy::make_embree_geometry(*s.query, *s.table, cfg);
  ivy::Grower g(s.scene, *geometry, *s.table, cfg, 1);
  const auto t0 = std::chrono::steady_clock::now();
  while (g.plant().nodes.size() < budget && g.step()) {
  }
  GrowResult r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.nodes = g.plant().nodes.size();
  r.bytes_per_node = g.state_bytes_per_node();
  if (keep_positions)
    for (const auto& n : g.plant().nodes) r.positions.push_back(n.position);
  return r;
}

// kWarm: every benchmark grows once untimed first. A first grow touches fresh pages as the node
// arrays double, and page faults are slow on these VMs; later grows reuse the freed memory
// (bench_main.cpp keeps glibc from handing it back). Without the warm-up whichever row ran first paid
// for all of them (the wall looked much faster on 2 threads than on 1).
//
// Unlimited root length: on a closed mesh roots never die, so any node budget is reachable.
const std::vector<std::string> kUnlimited = {"max_root_length=0"};

void BM_IvyGrowth(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  const auto threads = static_cast<std::size_t>(state.range(1));
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  IvyScene& s = ivy_scene(which);
  const std::vector<std::string> sets = which == 0 ? std::vector<std::string>{} : kUnlimited;
  GrowResult r = grow(s, 300000, sets);  // warm-up, see kWarm
  double total = 0.0;
  for (auto _ : state) {
    r = grow(s, 300000, sets);
    total += r.seconds;
    state.SetIterationTime(r.seconds);
  }
  state.counters["nodes"] = static_cast<double>(r.nodes);
  state.counters["nodes_per_s"] = static_cast<double>(r.nodes) * static_cast<double>(state.iterations()) / total;
  state.counters["ns_per_node"] =
      1e9 * total / (static_cast<double>(r.nodes) * static_cast<double>(state.iterations()));
  state.counters["state_B_per_node"] = r.bytes_per_node;
  state.SetLabel(which == 0 ? "wall" : "bunny");
}
BENCHMARK(BM_IvyGrowth)
    ->ArgNames({"scene", "threads"})
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

// What a node costs against the two queries it stands in for: one closest-point query bounded by the
// adhesion distance and one ray of one step, at the positions the ivy actually grew through.
void BM_IvyNodeVsQueries(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
  IvyScene& s = ivy_scene(which);
  const std::vector<std::string> sets = which == 0 ? std::vector<std::string>{} : kUnlimited;
  Params p = default_params(find_algorithm("ivy"));
  for (const auto& a : sets) p.set_assignment(a);
  const ivy::Config cfg = ivy::make_config(p, s.scene);
  double node_ns = 0.0, query_ns = 0.0;
  for (auto _ : state) {
    const GrowResult r = grow(s, 200000, sets, true);
    node_ns = 1e9 * r.seconds / static_cast<double>(r.nodes);
    float sink = 0.0f;
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t i = 1; i < r.positions.size(); ++i) {
      const glm::vec3& a = r.positions[i - 1];
      const ClosestHit h = s.query->closest_point(a, cfg.max_adhesion);
      const RayHit ray = s.query->ray(a, r.positions[i] - a, 1.0f);
      sink += h.distance + ray.t;
    }
    benchmark::DoNotOptimize(sink);
    query_ns = 1e9 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
               static_cast<double>(r.positions.size() - 1);
    state.SetIterationTime(r.seconds);
  }
  state.counters["node_ns"] = node_ns;
  state.counters["query_plus_ray_ns"] = query_ns;
  state.counters["ratio"] = node_ns / query_ns;
  state.SetLabel(which == 0 ? "wall" : "bunny");
}
BENCHMARK(BM_IvyNodeVsQueries)
    ->ArgName("scene")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

// Scaling on the bunny (one thread): time per node must stay flat from 10k to 1M nodes.
void BM_IvyScaling(benchmark::State& state) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
  IvyScene& s = ivy_scene(1);
  GrowResult r = grow(s, static_cast<std::size_t>(state.range(0)), kUnlimited);  // warm-up, see kWarm
  for (auto _ : state) {
    r = grow(s, static_cast<std::size_t>(state.range(0)), kUnlimited);
    state.SetIterationTime(r.seconds);
  }
  state.counters["nodes"] = static_cast<double>(r.nodes);
  state.counters["ns_per_node"] = 1e9 * r.seconds / static_cast<double>(r.nodes);
  state.counters["state_B_per_node"] = r.bytes_per_node;
}
BENCHMARK(BM_IvyScaling)
    ->ArgName("nodes")
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace growbench
