#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "algorithms/algorithm.hpp"

namespace growbench {

// What `growbench lsystem FILE --print` shows: the derived string (of the first plant) and its symbol
// counts, without drawing (the turtle runs only if rules read its state).
struct DerivedString {
  std::string text;  // up to print_limit modules (0: all)
  std::size_t modules = 0;
  std::size_t params = 0;
  std::size_t bytes = 0;  // memory of the string
  int generations = 0;
  std::vector<std::pair<char, std::size_t>> counts;  // by symbol, in ASCII order
};
DerivedString derive_lsystem(const Params& params, std::uint64_t seed, const Scene* scene, const SceneQuery* query,
                             std::size_t print_limit);

// Resolves a grammar name: an existing path, else an example under algorithms/lsystem/examples
// ("bush" or "bush.lsys"). InputError listing the examples otherwise.
std::string resolve_grammar_path(const std::string& name);
std::vector<std::string> lsystem_examples();

}  // namespace growbench
