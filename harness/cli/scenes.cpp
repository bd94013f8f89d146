// growbench scenes: the standard scenes, mesh scenes and scene files, with their parameters.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "harness/cli/command.hpp"
#include "harness/cli/param_table.hpp"
#include "harness/report/columns.hpp"
#include "scenes/scene_library.hpp"

namespace growbench::cli {

namespace {

Outcome list_scenes() {
  for (const auto& s : standard_scenes()) {
    fmt::print("{}\n{}", s.name, wrap_text(s.summary, "  ", "  "));
    print_param_table(s.params);
  }
  fmt::print("mesh:PATH.obj or mesh:NAME\n{}",
             wrap_text(fmt::format("any OBJ file, or a mesh the repository carries ({}); fitted to the standard size "
                                   "unless size=0, on a ground slab unless ground=false; one seed at the foot of its "
                                   "lit side (or --seed-at)",
                                   fmt::join(bundled_meshes(), ", ")),
                       "  ", "  "));
  print_param_table(mesh_scene_params());
  fmt::print("FILE.json\n{}", wrap_text("a scene file (schema_version 1): meshes, seeds, light, envelope, zones, "
                                        "camera; see scenes/README.md",
                                        "  ", "  "));
  return Outcome::ok;
}

}  // namespace

Command add_scenes(CLI::App& app) {
  return {app.add_subcommand("scenes", "List the standard scenes and their parameters"), list_scenes};
}

}  // namespace growbench::cli
