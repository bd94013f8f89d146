#include "algorithms/plant.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <memory>

#include <fmt/format.h>
#include <xxhash.h>

#include "scenes/scene.hpp"

namespace growbench {

const char* to_string(OrganKind k) {
  switch (k) {
    case OrganKind::Leaf:
      return "leaf";
    case OrganKind::YoungLeaf:
      return "young_leaf";
    case OrganKind::Flower:
      return "flower";
    case OrganKind::Bud:
      return "bud";
  }
  return "?";
}

std::size_t Plant::leaf_count() const {
  std::size_t n = 0;
  for (const auto& o : organs) n += (o.kind == OrganKind::Leaf || o.kind == OrganKind::YoungLeaf) ? 1 : 0;
  return n;
}

double Plant::total_length() const {
  double len = 0.0;
  for (const auto& n : nodes)
    if (n.parent != kNoParent) len += glm::length(n.position - nodes[static_cast<std::size_t>(n.parent)].position);
  return len;
}

std::string Plant::geometry_hash() const {
  // Fields are gathered in a small buffer and hashed a chunk at a time: the same value as feeding XXH3
  // field by field (it does not depend on how its input is split), at a fraction of the cost of many
  // tiny updates. The buffer is fixed and reused: one the size of the plant would be fresh memory, whose
  // page faults are slow on a VM.
  struct Hasher {
    XXH3_state_t* st = XXH3_createState();
    std::array<char, 1 << 14> buf{};
    std::size_t used = 0;
    Hasher() { XXH3_64bits_reset(st); }
    ~Hasher() { XXH3_freeState(st); }
    void flush() {
      XXH3_64bits_update(st, buf.data(), used);
      used = 0;
    }
    void bytes(const void* p, std::size_t n) {
      if (used + n > buf.size()) flush();
      if (n > buf.size()) {
        XXH3_64bits_update(st, p, n);
        return;
      }
      std::memcpy(buf.data() + used, p, n);
      used += n;
    }
  };
  auto hasher = std::make_unique<Hasher>();
  auto bytes = [&](const void* p, std::size_t n) { hasher->bytes(p, n); };
  auto put = [&](const auto& v) { bytes(&v, sizeof(v)); };
  put(nodes.size());
  for (const auto& n : nodes) {  // field by field: no padding bytes enter the hash
    put(n.position);
    put(n.radius);
    put(n.parent);
    put(n.order);
    put(n.shoot);
    put(n.birth_step);
  }
  put(organs.size());
  for (const auto& o : organs) {
    put(o.position);
    put(o.orientation);
    put(o.size);
    put(o.kind);
    put(o.node);
    put(o.stamp);
  }
  // Shapes and tints enter only when some organ has them, so plants without stay as they hashed before.
  if (organs_styled()) {
    put(organ_shapes.size());
    for (const auto& name : organ_shapes) {
      put(name.size());
      bytes(name.data(), name.size());
    }
    for (const auto& o : organs) {
      put(o.shape);
      put(o.tint);
    }
  }
  put(polygons.size());
  for (const auto& p : polygons) {
    put(p.vertices.size());
    for (const auto& v : p.vertices) put(v);
  }
  if (!node_groups.empty()) {
    put(node_groups.size());
    bytes(node_groups.data(), node_groups.size() * sizeof(std::int32_t));
  }
  for (const auto& a : node_attributes) {
    bytes(a.name.data(), a.name.size());
    put(a.components);
    bytes(a.values.data(), a.values.size() * sizeof(float));
  }
  // Added after the above existed: each enters only when present, so older plants keep their hashes.
  if (!node_tubes.empty()) {
    bytes("tubes", 5);
    put(node_tubes.size());
    for (const auto& t : node_tubes) {
      put(t.sections);
      put(t.divisions);
    }
  }
  if (!node_groups.empty() && !group_prefix.empty()) {
    bytes("prefix", 6);
    bytes(group_prefix.data(), group_prefix.size());
  }
  if (branch_geometry != BranchGeometry::Tube) {
    bytes("geometry", 8);
    put(branch_geometry);
  }
  if (tube_style != TubeStyle{}) {
    bytes("tubestyle", 9);
    put(tube_style.tension);
    put(tube_style.branch_blend);
    put(tube_style.uvs);
    put(tube_style.v_increment);
  }
  hasher->flush();
  return fmt::format("{:016x}", XXH3_64bits_digest(hasher->st));
}

std::string Plant::validate() const {
  // Within the scene's bounds, so that every query, mesher and exporter takes them (NaN fails too).
  auto near = [](const glm::vec3& v) { return glm::all(glm::lessThanEqual(glm::abs(v), glm::vec3(kMaxCoordinate))); };
  auto at = [](const glm::vec3& v) { return fmt::format("({}, {}, {})", v.x, v.y, v.z); };
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const auto& n = nodes[i];
    if (!near(n.position))
      return fmt::format("node {} lies at {}, not within {:g} m of the origin", i, at(n.position), kMaxCoordinate);
    if (!(n.radius >= 0.0f && n.radius <= kMaxCoordinate)) return fmt::format("node {} has radius {}", i, n.radius);
    if (n.parent != kNoParent && (n.parent < 0 || static_cast<std::size_t>(n.parent) >= i))
      return fmt::format("node {} has parent {} (parents must precede children)", i, n.parent);
  }
  for (std::size_t i = 0; i < organs.size(); ++i) {
    const auto& o = organs[i];
    if (!near(o.position) || !(o.size >= 0.0f && o.size <= kMaxCoordinate))
      return fmt::format("organ {} lies at {} with size {} (expected within {:g} m of the origin, size >= 0)", i,
                         at(o.position), o.size, kMaxCoordinate);
    if (!std::isfinite(o.stamp[0]) || !std::isfinite(o.stamp[1]) || !std::isfinite(o.stamp[2]))
      return fmt::format("organ {} has a non-finite stamp", i);
    // Exporters and the mesher turn organs by this quaternion as a rotation: one that is not unit would
    // scale a meshed organ but only turn an instanced one. The tolerance covers float rounding.
    const glm::quat& q = o.orientation;
    if (!(std::abs(glm::length(q) - 1.0f) <= 1e-3f))
      return fmt::format("organ {} has orientation (w {}, x {}, y {}, z {}), not a unit quaternion", i, q.w, q.x, q.y,
                         q.z);
    if (o.node != kNoParent && (o.node < 0 || static_cast<std::size_t>(o.node) >= nodes.size()))
      return fmt::format("organ {} refers to node {} of {}", i, o.node, nodes.size());
    if (o.shape != kKindShape && o.shape >= organ_shapes.size())
      return fmt::format("organ {} has shape {} of {}", i, o.shape, organ_shapes.size());
    if (!near(o.tint) || glm::any(glm::lessThan(o.tint, glm::vec3(0.0f))) ||
        glm::any(glm::greaterThan(o.tint, glm::vec3(4.0f))))
      return fmt::format("organ {} has tint ({}, {}, {}) outside [0, 4]", i, o.tint.x, o.tint.y, o.tint.z);
  }
  for (std::size_t i = 0; i < polygons.size(); ++i)
    for (std::size_t k = 0; k < polygons[i].vertices.size(); ++k)
      if (!near(polygons[i].vertices[k]))
        return fmt::format("polygon {} vertex {} lies at {}, not within {:g} m of the origin", i, k,
                           at(polygons[i].vertices[k]), kMaxCoordinate);
  if (organ_shapes.size() >= kKindShape)
    return fmt::format("{} organ shapes (at most {})", organ_shapes.size(), kKindShape - 1);
  for (std::size_t i = 0; i < organ_shapes.size(); ++i)
    if (organ_shapes[i].empty()) return fmt::format("organ shape {} has no name", i);
  for (std::size_t i = 0; i < decals.size(); ++i) {
    const auto& d = decals[i];
    // A plain file name: renders hand it to POV-Ray, which reads only below its working directory.
    if (d.image.empty() || d.image.find_first_of("/\\\"") != std::string::npos || d.image.front() == '.')
      return fmt::format("decal {} has image name '{}' (expected a plain file name)", i, d.image);
    if (d.mesh < kPlanarDecal || !near(d.origin) || !near(d.u_axis) || !near(d.v_axis))
      return fmt::format("decal {} has mesh {} or a non-finite mapping", i, d.mesh);
  }
  if (!node_groups.empty() && node_groups.size() != nodes.size())
    return fmt::format("{} node groups for {} nodes", node_groups.size(), nodes.size());
  for (const auto& a : node_attributes) {
    if (a.components < 1 || a.values.size() != nodes.size() * static_cast<std::size_t>(a.components))
      return fmt::format("attribute '{}' has {} values for {} nodes of {} components", a.name, a.values.size(),
                         nodes.size(), a.components);
    const auto v = std::find_if_not(a.values.begin(), a.values.end(), [](float x) { return std::isfinite(x); });
    if (v != a.values.end())
      return fmt::format("attribute '{}' has the non-finite value {} at {}", a.name, *v, v - a.values.begin());
  }
  if (!node_tubes.empty() && node_tubes.size() != nodes.size())
    return fmt::format("{} node tubes for {} nodes", node_tubes.size(), nodes.size());
  for (std::size_t i = 0; i < node_tubes.size(); ++i) {
    const TubeShape& t = node_tubes[i];
    if (t.sections > kMaxTubeSections)
      return fmt::format("node {} has {} tube sections (expected 0 to {})", i, t.sections, kMaxTubeSections);
    if (t.divisions != 0 && (t.divisions < kMinTubeDivisions || t.divisions > kMaxTubeDivisions))
      return fmt::format("node {} has {} tube divisions (expected 0, or {} to {})", i, t.divisions, kMinTubeDivisions,
                         kMaxTubeDivisions);
  }
  // The prefix names OBJ groups and glTF nodes: a word, so no reader splits or mangles it.
  for (const char c : group_prefix)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_'))
      return fmt::format("group prefix '{}' has a character other than letters, digits and '_'", group_prefix);
  if (branch_geometry != BranchGeometry::Tube && branch_geometry != BranchGeometry::Skeleton)
    return fmt::format("branch geometry {} is unknown", static_cast<int>(branch_geometry));
  const TubeStyle& t = tube_style;
  if (!(t.tension >= 0.0f && t.tension <= 1.0f) || !(t.branch_blend >= 0.0f && t.branch_blend <= 1.0f))
    return fmt::format("tube tension {} and branch blend {} (expected each in [0, 1])", t.tension, t.branch_blend);
  if (!std::isfinite(t.v_increment))
    return fmt::format("tube v increment {} (expected a finite number)", t.v_increment);
  return {};
}

bool Plant::organs_styled() const {
  return !organ_shapes.empty() || std::any_of(organs.begin(), organs.end(), [](const Organ& o) {
    return o.shape != kKindShape || o.tint != glm::vec3(1.0f);
  });
}

std::string Plant::group_name(std::int32_t g) const {
  return fmt::format("{}{}", group_prefix.empty() ? "group" : group_prefix, g);
}

void assign_pipe_radii(Plant& plant, float tip_radius, float exponent) {
  const std::size_t n = plant.nodes.size();
  std::vector<double> sum(n, 0.0);  // sum of children's r^n
  std::vector<bool> has_child(n, false);
  // Parents precede children, so one backward sweep sees every child before its parent.
  for (std::size_t k = n; k-- > 0;) {
    auto& node = plant.nodes[k];
    const double rn = has_child[k] ? sum[k] : std::pow(double(tip_radius), double(exponent));
    node.radius = static_cast<float>(std::pow(rn, 1.0 / exponent));
    if (node.parent != kNoParent) {
      sum[static_cast<std::size_t>(node.parent)] += rn;
      has_child[static_cast<std::size_t>(node.parent)] = true;
    }
  }
}

}  // namespace growbench
