// One mesher for every algorithm: tubes along branches from node radii, leaves and flowers as
// instanced shapes, L-system polygons as fans.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "algorithms/plant.hpp"
#include "scenes/scene.hpp"

namespace growbench {

struct MeshGroup {
  MeshGroup() = default;
  // A part of triangles (the form every part had before lines and plant groups; brace lists keep working).
  MeshGroup(std::string n, std::string mat, std::uint32_t first, std::uint32_t count)
      : name(std::move(n)), material(std::move(mat)), first_triangle(first), triangle_count(count) {}
  std::string name;      // "branches", "leaves", "flowers", "polygons"
  std::string material;  // "bark", "leaf", "flower"
  std::uint32_t first_triangle = 0;
  std::uint32_t triangle_count = 0;
  // The plant's own group this part belongs to (Plant::group_name of an L-system g), empty for none.
  // Exporters write it as an OBJ group beside `name` and as a glTF node of its own.
  std::string plant_group;
  std::uint32_t first_line = 0;  // line segments (OutputMesh::lines) of the part: branch geometry skeleton
  std::uint32_t line_count = 0;
};

// The base colour of each material, linear RGB, defined in one place (kMaterials in mesher.cpp): the
// OBJ materials' Kd, the glTF materials' base colour, and the colour mesh_plant gives the vertices of a
// part without colours of its own when another part has them. Unknown materials are mid grey.
struct MaterialColor {
  const char* material;
  double r, g, b;
};
const std::vector<MaterialColor>& material_colors();
glm::vec3 material_color(const std::string& material);

// A float attribute per vertex (the L-system's a("NAME", ...) other than Cd): `components` values per
// position; 0 on vertices of parts that do not carry it (the reference's "zero defaults").
struct VertexAttribute {
  std::string name;
  int components = 1;
  std::vector<float> values;
};

struct OutputMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::uvec3> triangles;
  std::vector<glm::uvec2> lines;  // line segments (Plant::branch_geometry skeleton), in the groups' ranges
  std::vector<MeshGroup> groups;
  // Linear RGB per vertex: empty when nothing in the plant is coloured, else one per position (organ
  // petal colours with their jitter, the L-system's a("Cd", r, g, b)); exporters write them when present.
  // A part that colours its vertices calls pad_colors before adding them and then pushes one colour per
  // vertex it adds; mesh_plant gives the vertices left without one their group's material_color.
  std::vector<glm::vec3> colors;
  std::vector<VertexAttribute> attributes;  // each empty or complete, as colors
};

// Marks the vertices so far that have no colour as uncoloured (see OutputMesh::colors).
void pad_colors(OutputMesh& m);

struct MesherOptions {
  int sides = 6;                       // tube cross-section sides (3..64)
  bool caps = true;                    // close tube ends
  float min_radius = 0.0f;             // radii below this are raised to it (0: as given; zero-radius nodes get 1e-4 m)
  std::string leaf_shape = "diamond";  // "diamond", "quad"; ignored when leaf_mesh has triangles
  TriangleMesh leaf_mesh;              // optional instanced leaf: local frame as Organ (+Z blade, +Y up), unit length
  std::string leaf_obj;                // an OBJ to load into leaf_mesh (load_leaf_mesh) when a trial or render starts
};

// A custom leaf from an OBJ file, as every algorithm's leaves and flowers are instanced: authored in the
// organ's frame, the blade along +Z from the stem and the upper side toward +Y. It is moved so its lowest
// z is 0 and scaled so its length along z is 1 (the organ's size then sizes it). InputError naming the
// file when it cannot be read, has no faces, or has no length along z.
TriangleMesh load_leaf_mesh(const std::string& path);

// options with leaf_mesh loaded from leaf_obj (when it names a file and leaf_mesh is empty).
MesherOptions with_leaf_mesh(MesherOptions options);

OutputMesh mesh_plant(const Plant& plant, const MesherOptions& options = {});

// The shape every leaf and flower is instanced from (options.leaf_mesh, else the named leaf_shape), in
// the organ's local frame at unit length. Shared with the POV-Ray writer so renders match the meshes.
TriangleMesh organ_shape(const MesherOptions& options = {});

// A point of an organ's shape (its local frame, unit length) placed in the world: scaled by the organ's
// size, turned by its orientation, moved to its position. Meshes, renders, the metrics' leaf overlap and
// self-shadowing all place organs through it, so they judge the organs that are exported.
glm::vec3 organ_point(const Organ& organ, const glm::vec3& local);

// Chains of nodes along which tubes run: each starts at a root or a branching point and follows the
// main child (the one that continues the parent's shoot, else the first). Shared with the skeleton
// exporter so polylines and tubes agree.
std::vector<std::vector<std::int32_t>> plant_chains(const Plant& plant);

}  // namespace growbench
