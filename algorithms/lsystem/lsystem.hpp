#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "algorithms/algorithm.hpp"

namespace growbench {

// The L-system's StringRewriting (algorithms/algorithm.hpp), for its own tests and fuzz target.
DerivedString derive_lsystem(const Params& params, std::uint64_t seed, const Scene* scene, const SceneQuery* query,
                             std::optional<std::size_t> print_limit);

// Resolves a grammar name: an existing path, else an example under algorithms/lsystem/examples
// ("bush" or "bush.lsys"). InputError listing the examples otherwise.
std::string resolve_grammar_path(const std::string& name);
std::vector<std::string> lsystem_examples();

}  // namespace growbench
