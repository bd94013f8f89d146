// The organ pass after growth: avoid placement over 100k candidate organs (leaves and blossoms on a
// branching skeleton), and the variation draws. The target for placement is under 1 s on 2 cores.
#define GLM_ENABLE_EXPERIMENTAL  // glm::rotation (shortest arc between two vectors)
#include <benchmark/benchmark.h>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/quaternion.hpp>
#include <tbb/global_control.h>

#include "core/random.hpp"
#include "harness/organs/placement.hpp"

namespace growbench {
namespace {

// Random-walk shoots in a 3 m box, each node carrying organs that point away from it in random
// directions: a quarter of them blossoms, the rest leaves, dense enough that many meet.
Plant crowded_plant(std::size_t organs) {
  Plant p;
  Rng rng(11, 3);
  const std::size_t shoots = organs / 100, per_shoot = 50;
  for (std::size_t s = 0; s < shoots; ++s) {
    glm::vec3 at(rng.uniform(0, 3), rng.uniform(0, 3), rng.uniform(0, 3));
    std::int32_t parent = kNoParent;
    for (std::size_t k = 0; k < per_shoot; ++k) {
      p.nodes.push_back({at, 0.004f, parent, 0, static_cast<std::uint32_t>(s), 0});
      parent = static_cast<std::int32_t>(p.nodes.size() - 1);
      at += 0.03f * rng.unit_vector();
    }
  }
  for (std::size_t i = 0; i < organs; ++i) {
    Organ o;
    o.node = static_cast<std::int32_t>(rng.next_u64() % p.nodes.size());
    o.position = p.nodes[static_cast<std::size_t>(o.node)].position;
    const glm::vec3 a = rng.unit_vector();
    o.orientation = glm::normalize(glm::angleAxis(static_cast<float>(rng.uniform(0, 6.283)), a) *
                                   glm::rotation(glm::vec3(0, 0, 1), rng.unit_vector()));
    o.size = 0.04f;
    o.kind = i % 4 == 3 ? OrganKind::Flower : OrganKind::Leaf;
    p.organs.push_back(o);
  }
  return p;
}

void BM_PlaceOrgansAvoid(benchmark::State& state) {
  const Plant grown = crowded_plant(static_cast<std::size_t>(state.range(0)));
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(1)));
  const OrganOptions opt = read_organ_options({"placement=avoid"});
  PlacementCounts c;
  for (auto _ : state) {
    state.PauseTiming();
    Plant p = grown;
    state.ResumeTiming();
    c = place_organs(p, opt);
    benchmark::DoNotOptimize(p.organs.data());
  }
  state.counters["placed"] = static_cast<double>(c.placed);
  state.counters["fallen_back"] = static_cast<double>(c.fallen_back);
  state.counters["dropped"] = static_cast<double>(c.dropped);
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
// Wall time is the target; the CPU column is every thread's, which a loaded machine stretches less.
BENCHMARK(BM_PlaceOrgansAvoid)
    ->ArgNames({"organs", "threads"})
    ->Args({10'000, 2})
    ->Args({100'000, 1})
    ->Args({100'000, 2})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

void BM_VaryOrgans(benchmark::State& state) {
  const Plant grown = crowded_plant(100'000);
  const OrganOptions opt =
      read_organ_options({"scale_min=0.8", "scale_max=1.2", "roll_deg=30", "tilt_deg=15", "color_jitter=0.1"});
  for (auto _ : state) {
    state.PauseTiming();
    Plant p = grown;
    state.ResumeTiming();
    vary_organs(p, opt, 1);
    benchmark::DoNotOptimize(p.organs.data());
  }
  state.SetItemsProcessed(state.iterations() * 100'000);
}
BENCHMARK(BM_VaryOrgans)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace growbench
