// Parameter values as they reach a table: `--set key=value` from the command line (text) and the values of
// a suite's "params" and sweeps (JSON), against the real tables of every algorithm and scene.
//
// Input: the first line names the table (an algorithm, a standard scene, or "mesh" for mesh scenes); each
// further line is an assignment "key=value" (Params::set_assignment), or "@key JSON" (Params::set_json; a
// line whose JSON does not parse is skipped: parsing JSON is the suite reader's part). Then every value is
// read back through its typed getter, and the whole as the trial record stores it.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "algorithms/algorithm.hpp"
#include "fuzz/fuzz_util.hpp"
#include "scenes/scene_library.hpp"

namespace {

using growbench::Params;

std::optional<Params> table(const std::string& name) {
  for (const auto* e : growbench::all_algorithms())
    if (e->info().name == name) return growbench::default_params(*e);
  for (const auto& s : growbench::standard_scenes())
    if (s.name == name) return Params("scene '" + name + "'", s.params);
  if (name == "mesh") return Params("scene 'mesh:x'", growbench::mesh_scene_params());
  return std::nullopt;
}

void apply_line(Params& p, const std::string& line) {
  if (line.empty() || line[0] != '@') {
    p.set_assignment(line);
    return;
  }
  const auto space = line.find(' ');
  const std::string key = line.substr(1, space == std::string::npos ? std::string::npos : space - 1);
  const auto value = nlohmann::json::parse(space == std::string::npos ? "" : line.substr(space + 1), nullptr, false);
  if (!value.is_discarded()) p.set_json(key, value);
}

void read_back(const Params& p) {
  using growbench::ParamType;
  for (const auto& s : p.specs()) {
    switch (s.type) {
      case ParamType::Int:
        (void)p.integer(s.name);
        break;
      case ParamType::Real:
        (void)p.real(s.name);
        break;
      case ParamType::Bool:
        (void)p.boolean(s.name);
        break;
      case ParamType::String:
      case ParamType::Choice:
        (void)p.text(s.name);
        break;
      case ParamType::Vec3:
        (void)p.vec3(s.name);
        break;
    }
  }
  (void)p.to_json();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  std::string line;
  std::getline(in, line);
  std::optional<Params> p = table(line);
  if (!p) return -1;  // not a table: kept out of the corpus
  while (std::getline(in, line)) growbench::fuzz::expect_input_errors([&] { apply_line(*p, line); });
  read_back(*p);
  return 0;
}
