// The plant every algorithm produces: a forest of nodes, leaves/flowers, and optional polygons.
// One mesher, one set of metrics and one renderer serve all algorithms through it.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace growbench {

constexpr std::int32_t kNoParent = -1;

struct PlantNode {
  glm::vec3 position{0.0f};
  float radius = 0.0f;
  std::int32_t parent = kNoParent;  // index of the parent node, kNoParent for a root
  std::uint16_t order = 0;          // branch order: 0 on the main axis, +1 per lateral branch
  std::uint32_t shoot = 0;          // shoot (branch) id: nodes of one unbranched axis share it
  std::uint32_t birth_step = 0;     // growth step at which the node appeared
};

enum class OrganKind : std::uint8_t { Leaf, YoungLeaf, Flower, Bud };
const char* to_string(OrganKind k);

// Organ::shape when the organ takes its kind's default shape (algorithms/organ_shapes.hpp).
constexpr std::uint16_t kKindShape = 0xFFFF;

// A leaf or flower. Local frame: +Z along the blade (from the stalk to the tip), +Y the upper-side
// normal, +X across; `size` is the blade length.
struct Organ {
  glm::vec3 position{0.0f};
  glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f};
  float size = 0.0f;
  OrganKind kind = OrganKind::Leaf;
  std::int32_t node = kNoParent;     // the node it grows from (or kNoParent)
  std::array<float, 3> stamp{};      // user values carried to the instanced geometry (L-system J/K/M a, b, c)
  std::uint16_t shape = kKindShape;  // index into Plant::organ_shapes, or kKindShape
  glm::vec3 tint{1.0f};              // factor on its shape's colour (colour jitter), each in [0, 4]
};

// A planar polygon (L-system { . } blocks).
struct PlantPolygon {
  std::vector<glm::vec3> vertices;
};

// A per-node float attribute (L-system a("Cd", r, g, b)): `components` values per node.
struct NodeAttribute {
  std::string name;
  int components = 1;
  std::vector<float> values;
};

// The tube an L-system F(l, w, s, d) asks for on the segment that ends at a node: `sections` cross
// sections along it and `divisions` around it; 0 leaves either to the mesher (one section, its sides).
struct TubeShape {
  std::uint16_t sections = 0;   // 0 or 1..kMaxTubeSections
  std::uint16_t divisions = 0;  // 0 or kMinTubeDivisions..kMaxTubeDivisions
};
constexpr int kMaxTubeSections = 64, kMinTubeDivisions = 3, kMaxTubeDivisions = 64;

// What the mesher makes of the branches: tubes around them, or their polylines alone (Houdini's
// Geometry Type Skeleton).
enum class BranchGeometry : std::uint8_t { Tube, Skeleton };

// How tubes run between their nodes and whether they carry texture coordinates (Houdini's Tube options).
// The default keeps every tube as it was before these existed: rings on the straight segment, no UVs.
struct TubeStyle {
  // Of the rings inside a segment cut into sections: 1 puts them on the straight segment at equal steps;
  // below 1 they follow a cardinal spline through the nodes, whose tangents are (1 - tension) times the
  // central difference, so 0 sweeps most smoothly.
  float tension = 1.0f;
  // How much a side branch's first segment leaves along its parent's direction (0: its own straight line;
  // 1: the tangent at the branch point is the parent's heading).
  float branch_blend = 0.0f;
  // Texture coordinates: u runs once around each ring (with a seam vertex), v grows by v_increment per
  // segment from the root (Houdini's Vertical Increment), so that a bark image tiles along the branches.
  bool uvs = false;
  float v_increment = 1.0f;
  bool operator==(const TubeStyle&) const = default;
  [[nodiscard]] bool curved() const { return tension != 1.0f || branch_blend != 0.0f; }
};

// An image an algorithm paints over the scene's surfaces (the vines' texture). Renders lay it over the
// surfaces' own material, and it stands for the plant there: a plant with decals is drawn by them.
// The image's (u, v) cover [0, 1]^2 with v up: its top row is v = 1, as in OBJ texture coordinates.
struct SurfaceDecal {
  std::string image;  // PNG file name, relative to the directory of the file that holds the plant
  // mesh >= 0: the image follows that scene mesh's texture coordinates (TriangleMesh::uvs). It covers
  // the unit square of them, or, when u_axis.x and v_axis.y are positive, the rectangle from
  // (origin.x, origin.y) to (origin.x + u_axis.x, origin.y + v_axis.y) (a layout beyond the unit square).
  // mesh == kPlanarDecal: (u, v) sits at origin + u * u_axis + v * v_axis and is projected along
  // u_axis x v_axis onto the climbable meshes; in a scene with none, that rectangle itself wears it.
  std::int32_t mesh = -1;
  glm::vec3 origin{0.0f}, u_axis{1.0f, 0.0f, 0.0f}, v_axis{0.0f, 1.0f, 0.0f};
};
constexpr std::int32_t kPlanarDecal = -1;

struct Plant {
  std::vector<PlantNode> nodes;
  std::vector<Organ> organs;
  std::vector<PlantPolygon> polygons;
  std::vector<SurfaceDecal> decals;
  // The shapes organs name by Organ::shape: a built-in shape's name or an OBJ file's path
  // (algorithms/organ_shapes.hpp resolves them). Empty when every organ takes its kind's shape.
  std::vector<std::string> organ_shapes;
  // Optional per-node data, empty unless an algorithm fills it (one entry per node when present):
  std::vector<std::int32_t> node_groups;  // group number (-1: none); L-system g
  std::vector<NodeAttribute> node_attributes;
  std::vector<TubeShape> node_tubes;  // L-system F(l, w, s, d)
  // Group g of node_groups is named group_prefix + g (group_name); letters, digits and '_' only.
  std::string group_prefix;
  BranchGeometry branch_geometry = BranchGeometry::Tube;
  TubeStyle tube_style;

  void clear() {
    nodes.clear();
    organs.clear();
    polygons.clear();
    decals.clear();
    organ_shapes.clear();
    node_groups.clear();
    node_attributes.clear();
    node_tubes.clear();
    group_prefix.clear();
    branch_geometry = BranchGeometry::Tube;
    tube_style = {};
  }
  // The name of group g (>= 0): group_prefix + g, or "group" + g without a prefix.
  [[nodiscard]] std::string group_name(std::int32_t g) const;
  [[nodiscard]] std::size_t leaf_count() const;
  [[nodiscard]] double total_length() const;  // sum of segment lengths (node to parent)
  // A hash of the canonical content (positions, radii, topology, organs, polygons, and the optional
  // per-node data, group prefix, branch geometry and tube style when present) as 16 hex digits. Equal hashes mean
  // bit-identical plants; a plant without the optional data hashes as it did before they existed.
  [[nodiscard]] std::string geometry_hash() const;
  // Whether some organ has a shape or tint of its own (what hashes and snapshots then carry).
  [[nodiscard]] bool organs_styled() const;
  // Checks the forest's invariants (parents precede children, finite values, non-negative radii);
  // returns an empty string when valid, otherwise the first violation.
  [[nodiscard]] std::string validate() const;
};

// Pipe-model radii (r^n = sum of children's r^n) from tip radius r_tip; exponent n in [1, 4].
void assign_pipe_radii(Plant& plant, float tip_radius, float exponent);

}  // namespace growbench
