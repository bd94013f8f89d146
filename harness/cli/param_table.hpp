// A parameter table as `growbench list` and `growbench scenes` print it.
#pragma once

#include <vector>

#include "core/params.hpp"

namespace growbench::cli {

void print_param_table(const std::vector<ParamSpec>& specs);

}  // namespace growbench::cli
