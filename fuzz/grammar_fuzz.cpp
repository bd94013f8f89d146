// The L-system grammar file as `growbench run lsystem --set grammar=FILE` reads it: settings, variables,
// premise and rules parsed (and every expression compiled), then derived without drawing, which is
// where the compiled expressions run. max_symbols is set small so that each input stays quick to derive;
// a grammar file's own max_symbols then loses to it, as a user's --set would win.
#include <cstddef>
#include <cstdint>

#include "algorithms/algorithm.hpp"
#include "algorithms/lsystem/lsystem.hpp"
#include "fuzz/fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace growbench;
  const std::string path = fuzz::write_input("grammar.lsys", data, size);
  fuzz::expect_input_errors([&] {
    Params p = default_params(find_algorithm("lsystem"));
    p.set("grammar", path);
    p.set("max_symbols", "2000");
    (void)derive_lsystem(p, 1, nullptr, nullptr, 64);
  });
  return 0;
}
