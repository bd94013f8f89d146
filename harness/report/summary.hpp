// `growbench summary`: the tables of a results file as text.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "harness/record/record.hpp"

namespace growbench {

// Per scene, a table of algorithm cells by metric: medians and 95% intervals of timings, warnings on noise.
std::string summarize_results(const ResultsFile& results);
std::string summarize_results(const nlohmann::json& results);  // read with from_json first

}  // namespace growbench
