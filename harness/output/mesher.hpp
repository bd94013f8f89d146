// One mesher for every algorithm: tubes along branches from node radii, leaves and flowers as
// instanced shapes, L-system polygons as fans.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "algorithms/plant.hpp"
#include "algorithms/organ_shapes.hpp"
#include "scenes/scene.hpp"

namespace growbench {

struct MeshGroup {
  std::string name;      // "branches", "leaves", "flowers", "polygons"
  std::string material;  // "bark", "leaf", "flower"
  std::uint32_t first_triangle = 0;
  std::uint32_t triangle_count = 0;
};

struct OutputMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::uvec3> triangles;
  std::vector<MeshGroup> groups;
  // Linear RGB per vertex: empty when nothing in the plant is coloured, else one per position (organ
  // petal colours with their jitter, the L-system's a("Cd", r, g, b)); exporters write them when present.
  std::vector<glm::vec3> colors;
};

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

// Chains of nodes along which tubes run: each starts at a root or a branching point and follows the
// main child (the one that continues the parent's shoot, else the first). Shared with the skeleton
// exporter so polylines and tubes agree.
std::vector<std::vector<std::int32_t>> plant_chains(const Plant& plant);

}  // namespace growbench
