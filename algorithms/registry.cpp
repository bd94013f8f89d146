#include <algorithm>

#include <fmt/format.h>

#include "algorithms/algorithm.hpp"
#include "algorithms/hadrich/hadrich.hpp"
#include "algorithms/ivy/ivy.hpp"
#include "algorithms/lsystem/lsystem.hpp"
#include "algorithms/spacecol/spacecol.hpp"

namespace growbench {

const std::vector<AlgorithmEntry>& algorithm_registry() {
  static const std::vector<AlgorithmEntry> list = {
      {spacecol_info, make_spacecol},
      {lsystem_info, make_lsystem},
      {ivy_info, make_ivy},
      {hadrich_info, make_hadrich},
  };
  return list;
}

const AlgorithmEntry& find_algorithm(const std::string& name) {
  const auto& list = algorithm_registry();
  for (const auto& e : list)
    if (e.info().name == name) return e;
  std::vector<std::string> names;
  for (const auto& e : list) names.push_back(e.info().name);
  const std::string near = closest_match(name, names);
  throw InputError(fmt::format("unknown algorithm '{}'{}; expected one of {}", name,
                               near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near), fmt::join(names, ", ")));
}

Params default_params(const AlgorithmEntry& entry) {
  const auto& info = entry.info();
  Params p(fmt::format("algorithm '{}'", info.name), info.params);
  if (!info.presets.empty()) p.set_presets(info.presets);
  return p;
}

}  // namespace growbench
