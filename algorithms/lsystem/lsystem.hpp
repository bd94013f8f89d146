#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "algorithms/algorithm.hpp"

namespace growbench {

// What `growbench lsystem FILE --print` shows: the derived string (of the first plant) and its symbol
// counts, without drawing (the turtle runs only if rules read its state).
struct DerivedString {
  std::string text;  // up to print_limit modules (0: all); empty without a print_limit
  // From the parsed grammar to the last generation's string (the premise and every rewrite, with the
  // turtle runs that rules reading its state need): the work lindenmayer's iterate() does. Parsing the
  // grammar is reading input; the text and the counts are output.
  double seconds = 0.0;
  // The same span's CPU time, summed over threads: on a loaded machine the wall time also holds waiting.
  double cpu_seconds = 0.0;
  std::size_t modules = 0;
  std::size_t params = 0;
  std::size_t bytes = 0;  // memory of the string
  int generations = 0;
  std::vector<std::pair<char, std::size_t>> counts;  // by symbol, in ASCII order
};
DerivedString derive_lsystem(const Params& params, std::uint64_t seed, const Scene* scene, const SceneQuery* query,
                             std::optional<std::size_t> print_limit);

// Resolves a grammar name: an existing path, else an example under algorithms/lsystem/examples
// ("bush" or "bush.lsys"). InputError listing the examples otherwise.
std::string resolve_grammar_path(const std::string& name);
std::vector<std::string> lsystem_examples();

}  // namespace growbench
