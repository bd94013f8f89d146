// Every algorithm on every standard scene: invariants any plant must satisfy, and determinism across
// thread counts; and what every registration must hold. A new algorithm is covered by these tests as
// soon as it is in the registry.
#include <set>

#include <gtest/gtest.h>

#include "algorithms/algorithm.hpp"
#include "grow_util.hpp"
#include "harness/run/trial.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {
namespace {

using Case = std::tuple<std::string, std::string>;

class EveryAlgorithmEveryScene : public ::testing::TestWithParam<Case> {};

TEST_P(EveryAlgorithmEveryScene, InvariantsAndDeterminism) {
  const auto& [algorithm, scene] = GetParam();
  TrialSpec spec;
  spec.algorithm = algorithm;
  spec.scene = scene;
  spec.params = find_algorithm(algorithm).info().test_params;  // no node enters a solid, quickly
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

class EveryAlgorithm : public ::testing::TestWithParam<std::string> {};

// One declaration per fact: a parameter's default lives in the algorithm's table and nowhere else. A
// struct the parameters are read into that has a default member initializer would be a second
// declaration, free to disagree with the table; such a struct is not trivially default constructible,
// which the registration records.
TEST_P(EveryAlgorithm, ParamStructsKeepNoDefaults) {
  const AlgorithmEntry& e = find_algorithm(GetParam());
  ASSERT_FALSE(e.param_structs.empty());
  for (const ParamStruct& s : e.param_structs) {
    EXPECT_TRUE(s.trivially_default_constructible)
        << "algorithm '" << GetParam() << "': " << s.type
        << " has a default of its own (a default member initializer, or a member that constructs itself such "
           "as a container). The parameter table is the only place for defaults: remove the initializer and "
           "fill the member from Params.";
  }
}

// The test parameters are assignments the algorithm's own table accepts.
TEST_P(EveryAlgorithm, TestParamsAreValid) {
  const AlgorithmEntry& e = find_algorithm(GetParam());
  Params p = default_params(e);
  for (const auto& a : e.info().test_params) EXPECT_NO_THROW(p.set_assignment(a)) << a;
}

std::vector<std::string> algorithm_names() {
  std::vector<std::string> v;
  for (const auto& a : algorithm_registry()) v.push_back(a.info().name);
  return v;
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryAlgorithm, ::testing::ValuesIn(algorithm_names()),
                         [](const auto& info) { return info.param; });

// The registration names each struct as written (the failure message above shows it).
TEST(AlgorithmRegistry, SplitsTheStructList) {
  EXPECT_EQ(split_type_list("lsys::TurtleSettings, lsys::DeriveSettings", 2),
            (std::vector<std::string>{"lsys::TurtleSettings", "lsys::DeriveSettings"}));
  EXPECT_EQ(split_type_list("a::X<int, 2>, std::pair<int, f(1, 2)>", 2),
            (std::vector<std::string>{"a::X<int, 2>", "std::pair<int, f(1, 2)>"}));
  EXPECT_EQ(split_type_list("hadrich::Config", 1), std::vector<std::string>{"hadrich::Config"});
}

// find_algorithm returns the first of a name, so a second algorithm under it (a copied folder whose
// name was not changed) would never run.
TEST(AlgorithmRegistry, NamesAreUnique) {
  const auto names = algorithm_names();
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
}

}  // namespace
}  // namespace growbench
