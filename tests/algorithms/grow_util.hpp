#pragma once

#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "algorithms/algorithm.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"

namespace growbench::test {

// A test suite whose tests grow on the envelope scene, loaded and queried once for all of them.
class OnEnvelope : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new Scene(load_scene("envelope"));
    query_ = new SceneQuery(*scene_);
  }
  static void TearDownTestSuite() {
    delete query_;
    delete scene_;
  }
  static inline Scene* scene_ = nullptr;
  static inline SceneQuery* query_ = nullptr;
};

// Grows a plant with one algorithm to completion (or max_steps) with a given thread count.
inline Plant grow(const std::string& algorithm, const Scene& scene, const SceneQuery& query,
                  const std::vector<std::string>& sets, int threads = 0, std::uint64_t seed = 1, int max_steps = 5000,
                  std::vector<std::pair<std::string, double>>* stats = nullptr) {
  std::unique_ptr<tbb::global_control> gc;
  if (threads > 0)
    gc = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               static_cast<std::size_t>(threads));
  const AlgorithmEntry& e = find_algorithm(algorithm);
  Params p = default_params(e);
  for (const auto& s : sets) p.set_assignment(s);
  auto algo = e.make();
  algo->start(scene, query, p, seed);
  for (int i = 0; i < max_steps && algo->step(); ++i) {
  }
  algo->finish();
  if (stats) *stats = algo->stats();
  return algo->plant();
}

// Indices of the nodes inside a solid, by the scene query's exact test (the one the metrics use).
inline std::vector<std::size_t> nodes_inside_solids(const Plant& plant, const SceneQuery& q) {
  std::vector<std::size_t> inside;
  for (std::size_t i = 0; i < plant.nodes.size(); ++i)
    if (q.inside(plant.nodes[i].position)) inside.push_back(i);
  return inside;
}

}  // namespace growbench::test
