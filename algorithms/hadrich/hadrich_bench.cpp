// Hädrich climbing plants: the cost of one full step (light and tropisms at the tips, growth, new
// particles, shape matching, collision, anchors, velocities) at 10k and 100k particles, on 1 and 2
// threads, and the bytes each particle holds. The plant is grown once to the size (still growing: the
// pool is twice as large, so tips keep lengthening and spawning during the timed steps); the timed
// steps continue that same run.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <map>

#include <fmt/format.h>
#include <memory>

#include "algorithms/hadrich/hadrich.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {
namespace {

struct Grown {
  Scene scene;
  std::unique_ptr<SceneQuery> query;
  std::unique_ptr<hadrich::Simulator> sim;
};

// A wide wall with many seeds, so 100k particles grow in a few hundred steps.
// One plant per benchmark case (the thread count included), so each case times the same state.
Grown& grown(std::size_t particles, int which, std::size_t threads) {
  static std::map<std::tuple<std::size_t, int, std::size_t>, Grown> cache;
  Grown& g = cache[{particles, which, threads}];
  if (!g.sim) {
    if (which == 0) {
      g.scene = load_scene(
          "wall", {"width=12", "height=6", fmt::format("seeds={}", std::max<std::size_t>(3, particles / 2500))});
    } else {
      g.scene = load_scene("mesh:stanford-bunny");
    }
    g.query = std::make_unique<SceneQuery>(g.scene);
    if (which == 1) {
      g.scene.seeds.clear();
      for (int k = 0; k < static_cast<int>(std::max<std::size_t>(3, particles / 2500)); ++k) {
        const float a = 6.2831853f * static_cast<float>(k) / 8.0f;
        g.scene.seeds.push_back(
            {g.query->closest_point({std::cos(a), 0.3f + 0.05f * static_cast<float>(k % 5), std::sin(a)}).point,
             {0, 1, 0},
             0});
      }
    }
    Params p = default_params(find_algorithm("hadrich"));
    p.set_assignment(fmt::format("max_particles={}", 2 * particles));
    g.sim = std::make_unique<hadrich::Simulator>(g.scene, *g.query, hadrich::make_setup(p), 1);
    while (g.sim->particles().size() < particles && g.sim->step()) {
    }
  }
  return g;
}

void BM_HadrichStep(benchmark::State& state) {
  const auto particles = static_cast<std::size_t>(state.range(0));
  const auto threads = static_cast<std::size_t>(state.range(1));
  Grown& g = grown(particles, static_cast<int>(state.range(2)), threads);
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  const std::size_t start = g.sim->particles().size();
  for (auto _ : state) g.sim->step();
  double tips = 0.0;
  for (const auto& [k, v] : g.sim->stats())
    if (k == "tips") tips = v;
  state.counters["particles"] = static_cast<double>(start);
  state.counters["tips"] = tips;
  state.counters["bytes_per_particle"] = static_cast<double>(hadrich::Particles::bytes_per_particle());
  state.counters["steps"] = g.sim->steps();
}
// Args: particles, threads, scene (0: wall, 1: bunny). Real time: the steps run on TBB workers.
BENCHMARK(BM_HadrichStep)
    ->Args({10000, 1, 0})
    ->Args({10000, 2, 0})
    ->Args({100000, 1, 0})
    ->Args({100000, 2, 0})
    ->Args({10000, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(40);

}  // namespace
}  // namespace growbench
