// Where scenes come from: the standard scenes built in code, scene JSON files, and any OBJ file.
#pragma once

#include <string>
#include <vector>

#include "core/params.hpp"
#include "scenes/scene.hpp"

namespace growbench {

struct StandardScene {
  std::string name;
  std::string summary;
  std::vector<ParamSpec> params;
  Scene (*build)(const Params&);
};

// The eight standard scenes: wall, facade, column, corner, pergola, boulder, trunk, envelope.
const std::vector<StandardScene>& standard_scenes();
// Parameters of `mesh:PATH` scenes (size, ground).
const std::vector<ParamSpec>& mesh_scene_params();

// The test meshes the repository carries (scenes/meshes/), named by file stem: `mesh:stanford-bunny`.
// A mesh reference without a '/' and without an extension is such a name; anything else is a path.
bool is_mesh_name(const std::string& ref);
std::vector<std::string> bundled_meshes();
// The OBJ file a mesh reference names: a bundled mesh's file, or `ref` itself. Throws InputError for an
// unknown name, listing the bundled meshes.
std::string mesh_path(const std::string& ref);

// Loads a scene from a spec: a standard scene's name, a scene JSON file (*.json), or mesh:PATH for an OBJ
// (or mesh:NAME for a bundled mesh).
// `assignments` are key=value scene parameters (for standard and mesh scenes). Throws InputError.
Scene load_scene(const std::string& spec, const std::vector<std::string>& assignments = {});

// Reads an OBJ file as one triangle mesh (polygons are triangulated). Throws InputError naming the file.
TriangleMesh load_obj(const std::string& path);
// The same, as a scene's solid: a nearly closed mesh (a scan with a few small holes) is sealed
// (geom::fill_small_holes), so that what algorithms collide with, what renders show and what the
// metrics judge are one surface. Every mesh a scene reads from a file comes through here.
TriangleMesh load_scene_obj(const std::string& path);

// Uniformly scales `scene`'s meshes (and seeds, envelope, zones, camera) so the largest extent of the
// meshes' bounds is `size`, resting on y = 0 and centred on x = z = 0.
void fit_scene(Scene& scene, float size);

}  // namespace growbench
