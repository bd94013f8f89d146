// Costs of the scene queries every algorithm leans on (one thread, random points near the bunny).
#include <benchmark/benchmark.h>
#include <nanoflann.hpp>

#include "core/random.hpp"
#include "scenes/host_queries.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {
namespace {

struct Bunny {
  Scene scene = load_scene("mesh:stanford-bunny");
  SceneQuery query{scene};
  std::vector<glm::vec3> pts;
  Bunny() {
    const Aabb b = scene.bounds();
    Rng r(1, 1);
    pts.resize(1 << 14);
    for (auto& p : pts)
      p = b.min - 0.1f * b.size() + glm::vec3(r.uniform(), r.uniform(), r.uniform()) * 1.2f * b.size();
  }
};
Bunny& bunny() {
  static Bunny b;
  return b;
}

void BM_ClosestPoint(benchmark::State& state) {
  auto& b = bunny();
  const float radius = state.range(0) == 0 ? std::numeric_limits<float>::infinity() : 0.05f;
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(b.query.closest_point(b.pts[i++ & (b.pts.size() - 1)], radius));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ClosestPoint)->ArgName("bounded")->Arg(0)->Arg(1);

void BM_Ray(benchmark::State& state) {
  auto& b = bunny();
  std::size_t i = 0;
  const glm::vec3 c = b.scene.bounds().center();
  for (auto _ : state) {
    const glm::vec3 p = b.pts[i++ & (b.pts.size() - 1)];
    benchmark::DoNotOptimize(b.query.ray(p, c - p));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Ray);

void BM_SignedDistance(benchmark::State& state) {
  auto& b = bunny();
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(b.query.signed_distance(b.pts[i++ & (b.pts.size() - 1)]));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SignedDistance);

// One batched closest-point call of N points through the C++ host interface the built-ins use (DirectQueries):
// the per-call cost beside bench/python/query_cost.py's, the same call from Python with numpy.
void BM_ClosestPointsBatch(benchmark::State& state) {
  auto& b = bunny();
  const DirectQueries host(b.query);
  const auto n = static_cast<std::size_t>(state.range(0));
  const float radius = state.range(1) == 0 ? std::numeric_limits<float>::infinity() : 0.05f;
  std::vector<ClosestHit> out(n);
  for (auto _ : state) {
    host.closest_points({b.pts.data(), n}, radius, false, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_ClosestPointsBatch)->ArgNames({"points", "bounded"})->ArgsProduct({{1, 1024}, {0, 1}});

void BM_QueryBuild(benchmark::State& state) {
  const Scene s = load_scene("mesh:stanford-bunny");
  for (auto _ : state) {
    SceneQuery q(s);
    benchmark::DoNotOptimize(q.voxel_size());
  }
}
BENCHMARK(BM_QueryBuild)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace growbench
