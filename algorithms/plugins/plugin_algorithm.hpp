// A GrowthAlgorithm whose work is done by a plugin through the C ABI (include/growbench/plugin.h):
// the host's side of the boundary.
#pragma once

#include <memory>
#include <string>

#include "algorithms/algorithm.hpp"
#include "growbench/plugin.h"

namespace growbench {

// `table` must outlive the algorithm (plugins are never unloaded); `info` is its table as read once
// by the loader; `path` the file it came from, which its failures name (as PluginError).
std::unique_ptr<GrowthAlgorithm> make_plugin_algorithm(const growbench_plugin* table, const AlgorithmInfo& info,
                                                       const std::string& path);

}  // namespace growbench
