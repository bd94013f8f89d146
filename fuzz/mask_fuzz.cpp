// The vines' PNG inclusion/exclusion mask as `--set mask=FILE` reads it, then looked up as growth does.
#include <cstddef>
#include <cstdint>

#include "algorithms/vines/mask.hpp"
#include "fuzz/fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = growbench::fuzz::write_input("mask.png", data, size);
  growbench::fuzz::expect_input_errors([&] {
    const auto mask = growbench::vines::Mask::read(path, "mask");
    for (const float u : {-0.5f, 0.0f, 0.5f, 1.0f, 1.5f}) (void)mask.zone({u, 1.0f - u});
  });
  return 0;
}
