// What leaves, flowers and buds look like: the built-in organ shapes, organ OBJ files, and the colour
// each organ is drawn in. Algorithms name shapes in Plant::organ_shapes (and check the names when they
// start); the mesher, the POV-Ray writer, the metrics and the organ pass all take an organ's geometry
// from here, so they judge the organs that are exported.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "algorithms/plant.hpp"
#include "scenes/scene.hpp"

namespace growbench {

// One organ shape in the organ's frame (Organ: +Z from the stem toward the tip, +Y the upper side) at
// unit size: a leaf's blade and a bud are 1 long along +Z; a blossom is 1 across.
struct OrganShape {
  std::string name;  // a built-in's name, or the OBJ file's path
  TriangleMesh mesh;
  std::vector<glm::vec3> normals;          // per vertex, area-weighted
  bool has_color = false;                  // false: the organ takes its kind's colour (organ_kind_srgb)
  glm::vec3 srgb{1.0f};                    // the shape's own colour when it has one
  glm::vec3 box_min{0.0f}, box_max{0.0f};  // the vertices' bounds: the oriented box placement tests
};

// The built-ins, in the order `list` prints them: leaf, blossom, half_bloom, bud.
const std::vector<std::string>& builtin_organ_shape_names();
// One line about each built-in, in the same order.
const std::vector<std::string>& builtin_organ_shape_docs();
// A built-in by name; InputError naming `source` (the parameter that asked) and listing the built-ins.
OrganShape builtin_organ_shape(std::string_view name, std::string_view source = "organ shape");
// An OBJ authored in the organ's frame: moved so its lowest z is 0 and scaled so its length along z is 1.
// InputError naming the file when it cannot be read, has no faces, or has no length along z.
OrganShape load_organ_obj(const std::string& path);
// Whether a shape's name means an OBJ file (it ends in .obj, or contains a '/') rather than a built-in.
bool names_a_file(const std::string& name);
// A built-in's name or an OBJ file's path (anything ending in .obj, or containing a '/').
OrganShape organ_shape_named(const std::string& name_or_path, std::string_view source = "organ shape");

// A point of an organ's shape (its local frame, unit size) placed in the world: scaled by the organ's
// size, turned by its orientation, moved to its position. Meshes, renders, the metrics' leaf overlap,
// self-shadowing and the organ pass all place organs through it, so they judge the organs exported.
glm::vec3 organ_point(const Organ& organ, const glm::vec3& local);

// The sRGB colour of an organ kind when its shape has none (the same as the POV-Ray materials).
glm::vec3 organ_kind_srgb(OrganKind kind);
// sRGB to linear, per component (the exporters' vertex colours are linear).
glm::vec3 srgb_to_linear(const glm::vec3& srgb);

// The shape of each of a plant's organs: Plant::organ_shapes by index, and for an organ with
// kKindShape its kind's default. The defaults are `leaf` for leaves, `blossom` for flowers and `bud`
// for buds; a custom leaf (--leaf-obj) replaces all three.
class OrganShapes {
 public:
  OrganShapes(const Plant& plant, const OrganShape* custom_leaf = nullptr);
  [[nodiscard]] const OrganShape& of(const Organ& organ) const;
  // Every distinct shape, and the index of an organ's shape among them.
  [[nodiscard]] std::size_t size() const { return shapes_.size(); }
  [[nodiscard]] const OrganShape& at(std::size_t i) const { return *shapes_[i]; }
  [[nodiscard]] std::size_t index_of(const Organ& organ) const;
  // The linear colour an organ is drawn in: its shape's or its kind's, times its tint.
  [[nodiscard]] glm::vec3 linear_color(const Organ& organ) const;
  // True when some organ's colour is not its kind's plain colour (vertex colours are then worth writing).
  [[nodiscard]] bool any_color(const Plant& plant) const;

 private:
  std::vector<std::shared_ptr<const OrganShape>> shapes_;  // built-ins shared by every OrganShapes
  std::vector<std::size_t> named_;                         // Plant::organ_shapes[i] -> shapes_
  std::array<std::size_t, 4> kind_{};                      // OrganKind -> shapes_ (only the kinds the plant has)
};

}  // namespace growbench
