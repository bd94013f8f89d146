// The interface every growth algorithm implements. The harness drives the steps, so budgets, time
// limits, growth curves and animation frames work the same way for all of them.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "algorithms/plant.hpp"
#include "core/params.hpp"
#include "scenes/scene.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {

struct AlgorithmInfo {
  std::string name;
  std::string summary;
  std::vector<ParamSpec> params;  // the table `growbench list` prints
  std::vector<ParamPreset> presets;  // defaults selected by the `preset` parameter (may be empty)
};

class GrowthAlgorithm {
 public:
  virtual ~GrowthAlgorithm() = default;
  [[nodiscard]] virtual const AlgorithmInfo& describe() const = 0;
  // Prepares a run. `params` were validated against describe().params. The scene and query outlive
  // the algorithm. Throws InputError for combinations of parameters and scene that cannot work.
  virtual void start(const Scene& scene, const SceneQuery& query, const Params& params, std::uint64_t seed) = 0;
  // Advances one growth step; returns false when growth has ended by itself.
  virtual bool step() = 0;
  [[nodiscard]] virtual const Plant& plant() const = 0;
  // What the harness checks after every step (budgets, the growth curve), without asking for the
  // whole plant: an algorithm that assembles its Plant on demand (hadrich) answers from its own state.
  // Must equal plant().nodes.size() and plant().organs.size().
  [[nodiscard]] virtual std::size_t node_count() const { return plant().nodes.size(); }
  [[nodiscard]] virtual std::size_t organ_count() const { return plant().organs.size(); }
  // Called once after the last step, before meshing (e.g. to assign pipe-model radii or place leaves).
  virtual void finish() {}
  // Algorithm-specific figures for the trial record (e.g. attraction points left).
  [[nodiscard]] virtual std::vector<std::pair<std::string, double>> stats() const { return {}; }
};

struct AlgorithmEntry {
  const AlgorithmInfo& (*info)();
  std::unique_ptr<GrowthAlgorithm> (*make)();
};

// The explicit list of algorithms (algorithms/registry.cpp). Adding one is a folder plus one line there.
const std::vector<AlgorithmEntry>& algorithm_registry();
// Finds an algorithm by name; InputError listing the valid names otherwise.
const AlgorithmEntry& find_algorithm(const std::string& name);
// Default parameters of an algorithm, with `owner` set for error messages.
Params default_params(const AlgorithmEntry& entry);

}  // namespace growbench
