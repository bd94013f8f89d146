// An OBJ file as both of its readers take it: as a scene's solid (load_scene_obj: read, then small holes
// sealed) and as an organ's shape (load_organ_obj: read, then moved and scaled into the organ's frame).
#include <cstddef>
#include <cstdint>

#include "algorithms/organ_shapes.hpp"
#include "fuzz/fuzz_util.hpp"
#include "scenes/scene_library.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = growbench::fuzz::write_input("mesh.obj", data, size);
  growbench::fuzz::expect_input_errors([&] { (void)growbench::load_scene_obj(path); });
  growbench::fuzz::expect_input_errors([&] { (void)growbench::load_organ_obj(path); });
  return 0;
}
