// A scene JSON file as `growbench run ALGO --scene FILE.json` loads it: its keys, meshes, shapes and
// bases (a base may be a standard scene, a bundled mesh, or another scene file).
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_util.hpp"
#include "scenes/scene_library.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = growbench::fuzz::write_input("scene.json", data, size);
  growbench::fuzz::expect_input_errors([&] { (void)growbench::load_scene(path); });
  return 0;
}
