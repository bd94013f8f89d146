// One mesher for every algorithm: tubes along branches from node radii, leaves and flowers as
// instanced shapes, L-system polygons as fans.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "algorithms/plant.hpp"
#include "algorithms/organ_shapes.hpp"
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

// The base colour of each material, linear RGB (material_srgb's colours, linearised): the
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
  // Texture coordinates (OBJ convention, v up): empty unless the plant's TubeStyle asks for them, else one
  // per position, (0, 0) on vertices of parts without their own (organs, polygons).
  std::vector<glm::vec2> uvs;
  // The growth step at which each vertex's part of the plant appeared (PlantNode::birth_step of the node
  // a tube ring or skeleton vertex stands for, of an organ's node), one per position, so that a viewer can
  // show the plant as it grew. Not an `attributes` entry: it never reaches OBJ or PLY, and the glTF writer
  // keeps organs instanced with it (a per-instance value).
  std::vector<std::uint32_t> birth_steps;
};

// Marks the vertices so far that have no colour as uncoloured (see OutputMesh::colors).
void pad_colors(OutputMesh& m);

struct MesherOptions {
  int sides = 6;            // tube cross-section sides (3..64)
  bool caps = true;         // close tube ends
  float min_radius = 0.0f;  // radii below this are raised to it (0: as given; zero-radius nodes get 1e-4 m)
  // A custom organ OBJ (--leaf-obj): the shape of every leaf, flower and bud whose plant names none.
  std::string leaf_obj;
  std::shared_ptr<const OrganShape> leaf;  // leaf_obj, loaded by with_leaf_mesh
};

// options with `leaf` loaded from leaf_obj (when it names a file and nothing is loaded yet).
MesherOptions with_leaf_mesh(MesherOptions options);

// The shape of each of the plant's organs under these options (algorithms/organ_shapes.hpp).
OrganShapes organ_shapes(const Plant& plant, const MesherOptions& options = {});

// The sRGB base colour of a mesh group's material ("bark", "leaf", "flower"), as the renders draw it.
glm::vec3 material_srgb(std::string_view material);

OutputMesh mesh_plant(const Plant& plant, const MesherOptions& options = {});

// The growth step of the plant's newest node: when what stands for no node (an L-system polygon, an organ
// on no node) is taken to appear.
std::uint32_t last_birth_step(const Plant& plant);
// The growth step at which `organ` appeared: its node's, else `last_step`.
std::uint32_t organ_birth_step(const Plant& plant, const Organ& organ, std::uint32_t last_step);

// Chains of nodes along which tubes run: each starts at a root or a branching point and follows the
// main child (the one that continues the parent's shoot, else the first). Shared with the skeleton
// exporter so polylines and tubes agree.
std::vector<std::vector<std::int32_t>> plant_chains(const Plant& plant);

}  // namespace growbench
