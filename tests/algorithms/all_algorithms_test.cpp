// Every algorithm on every standard scene: invariants any plant must satisfy, and determinism across
// thread counts. A new algorithm is covered by this test as soon as it is in the registry.
#include <gtest/gtest.h>

#include "algorithms/algorithm.hpp"
#include "grow_util.hpp"
#include "harness/run/trial.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {
namespace {

// Parameters under which an algorithm promises that no node enters a solid, and a size that keeps the
// test quick.
std::vector<std::string> invariant_params(const std::string& algorithm) {
  if (algorithm == "spacecol") return {"surface=avoid", "point_count=4000"};
  if (algorithm == "lsystem") return {"surface=wrap"};  // a free tree would pass through solids
  if (algorithm == "ivy") return {"max_root_length=1"};
  if (algorithm == "hadrich") return {"max_particles=2000"};
  return {};
}

using Case = std::tuple<std::string, std::string>;

class EveryAlgorithmEveryScene : public ::testing::TestWithParam<Case> {};

TEST_P(EveryAlgorithmEveryScene, InvariantsAndDeterminism) {
  const auto& [algorithm, scene] = GetParam();
  TrialSpec spec;
  spec.algorithm = algorithm;
  spec.scene = scene;
  spec.params = invariant_params(algorithm);
  spec.max_steps = 3000;
  spec.threads = 1;
  Plant one, two;
  const auto r1 = run_trial(spec, {}, &one);
  spec.threads = 2;
  const auto r2 = run_trial(spec, {}, &two);
  EXPECT_EQ(r1["geometry_hash"], r2["geometry_hash"]) << "1 vs 2 threads";
  EXPECT_EQ(r1["scene"]["hash"], r2["scene"]["hash"]);
  EXPECT_EQ(one.validate(), "");  // finite, parents before children: a connected forest
  ASSERT_GT(one.nodes.size(), 10u) << "nothing grew";
  std::size_t roots = 0;
  for (const auto& n : one.nodes) roots += n.parent == kNoParent ? 1 : 0;
  const Scene s = load_scene(scene);
  EXPECT_EQ(roots, s.seeds.size()) << "one tree per seed";
  SceneQuery q(s);
  const auto inside = test::nodes_inside_solids(one, q);
  EXPECT_TRUE(inside.empty()) << inside.size() << " nodes inside a solid, the first is node " << inside.front()
                              << " at SDF " << q.signed_distance(one.nodes[inside.front()].position);
}

std::vector<Case> all_cases() {
  std::vector<Case> v;
  for (const auto& a : algorithm_registry())
    for (const auto& s : standard_scenes()) v.emplace_back(a.info().name, s.name);
  return v;
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryAlgorithmEveryScene, ::testing::ValuesIn(all_cases()),
                         [](const auto& info) { return std::get<0>(info.param) + "_" + std::get<1>(info.param); });

}  // namespace
}  // namespace growbench
