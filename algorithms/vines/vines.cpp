// Space-colonization vines in texture space (scaffolding; the growth is being written).
#include "algorithms/algorithm.hpp"

namespace growbench {
namespace {

const AlgorithmInfo kInfo = {
    .name = "vines",
    .summary = "space colonization in a texture's UV space: masks, tags, wiggle, kill limits, leaves",
    .params = {param::integer("resolution", 256).range(8, 8192).doc("vine resolution")},
    .test_params = {},
};

struct Config {
  int resolution;
};

class Vines final : public GrowthAlgorithm {
 public:
  const AlgorithmInfo& describe() const override { return kInfo; }
  void start(const Scene&, const SceneQuery&, const Params&, std::uint64_t) override {}
  bool step() override { return false; }
  const Plant& plant() const override { return plant_; }

 private:
  Plant plant_;
};

}  // namespace

GROWBENCH_REGISTER_ALGORITHM(vines, Vines, kInfo, Config)

}  // namespace growbench
