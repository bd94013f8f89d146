// A GrowthAlgorithm whose work is done by a plugin through the C ABI (include/growbench/plugin.h):
// the host's side of the boundary.
#pragma once

#include <memory>

#include "algorithms/algorithm.hpp"
#include "growbench/plugin.h"

namespace growbench {

// `table` must outlive the algorithm (plugins are never unloaded); `info` is its table as read once
// by the loader.
std::unique_ptr<GrowthAlgorithm> make_plugin_algorithm(const growbench_plugin* table, const AlgorithmInfo& info);

}  // namespace growbench
