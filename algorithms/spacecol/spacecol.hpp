#pragma once

#include <memory>

#include "algorithms/algorithm.hpp"

namespace growbench {

const AlgorithmInfo& spacecol_info();
std::unique_ptr<GrowthAlgorithm> make_spacecol();

}  // namespace growbench
