// A suite file as `growbench suite FILE` reads and checks it before anything runs: its algorithms,
// parameters, sweeps, scenes, organs and limits.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_util.hpp"
#include "harness/suite/suite.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = growbench::fuzz::write_input("suite.json", data, size);
  growbench::fuzz::expect_input_errors([&] { (void)growbench::load_suite(path); });
  return 0;
}
