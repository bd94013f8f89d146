#pragma once

#include <memory>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "algorithms/algorithm.hpp"
#include "scenes/scene_query.hpp"

namespace growbench::test {

// Grows a plant with one algorithm to completion (or max_steps) with a given thread count.
inline Plant grow(const std::string& algorithm, const Scene& scene, const SceneQuery& query,
                  const std::vector<std::string>& sets, int threads = 0, std::uint64_t seed = 1, int max_steps = 5000,
                  std::vector<std::pair<std::string, double>>* stats = nullptr) {
  std::unique_ptr<tbb::global_control> gc;
  if (threads > 0)
    gc = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
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

// Indices of the nodes inside a solid. The distance field is a voxel approximation: in a concave
// crease (a wall meeting the ground, the bunny's folds) it reads a few millimetres negative at points
// just outside, exactly where climbing plants creep. So a node counts as inside when the field puts it
// deeper than a voxel (creases read up to about 0.6 voxel), or when it reads negative at all and exact ray parity agrees (odd
// crossings along at least two of three directions; parity alone would miss a node inside two
// overlapping solids).
inline std::vector<std::size_t> nodes_inside_solids(const Plant& plant, const SceneQuery& q) {
  const glm::vec3 dirs[3] = {glm::normalize(glm::vec3(0.5773f, 0.6170f, 0.5348f)),
                             glm::normalize(glm::vec3(-0.3f, 0.2f, 0.93f)), glm::normalize(glm::vec3(0.1f, -0.9f, 0.4f))};
  std::vector<std::size_t> inside;
  for (std::size_t i = 0; i < plant.nodes.size(); ++i) {
    const glm::vec3 p = plant.nodes[i].position;
    const float sd = q.signed_distance(p);
    if (sd >= -1e-4f) continue;
    int odd = 0;
    for (const auto& d : dirs) {
      int crossings = 0;
      float t = 0.0f;
      for (RayHit h; (h = q.ray(p, d, 1e9f, t)).hit && crossings < 10000; t = h.t + 1e-6f) ++crossings;
      odd += crossings % 2;
    }
    if (sd < -q.voxel_size() || odd >= 2) inside.push_back(i);
  }
  return inside;
}

}  // namespace growbench::test
