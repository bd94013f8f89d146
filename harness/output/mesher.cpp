#include "harness/output/mesher.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>

#include "core/errors.hpp"
#include "scenes/scene_library.hpp"

namespace growbench {

std::vector<std::vector<std::int32_t>> plant_chains(const Plant& plant) {
  const std::size_t n = plant.nodes.size();
  std::vector<std::int32_t> main_child(n, kNoParent);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t p = plant.nodes[i].parent;
    if (p == kNoParent) continue;
    auto& mc = main_child[static_cast<std::size_t>(p)];
    const bool same_shoot = plant.nodes[i].shoot == plant.nodes[static_cast<std::size_t>(p)].shoot;
    if (mc == kNoParent) {
      mc = static_cast<std::int32_t>(i);
    } else if (same_shoot &&
               plant.nodes[static_cast<std::size_t>(mc)].shoot != plant.nodes[static_cast<std::size_t>(p)].shoot) {
      mc = static_cast<std::int32_t>(i);
    }
  }
  std::vector<std::vector<std::int32_t>> chains;
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t p = plant.nodes[i].parent;
    const bool starts = p == kNoParent || main_child[static_cast<std::size_t>(p)] != static_cast<std::int32_t>(i);
    if (!starts) continue;
    std::vector<std::int32_t> chain;
    if (p != kNoParent) chain.push_back(p);
    for (auto c = static_cast<std::int32_t>(i); c != kNoParent; c = main_child[static_cast<std::size_t>(c)])
      chain.push_back(c);
    if (chain.size() >= 2) chains.push_back(std::move(chain));
  }
  return chains;
}

namespace {

glm::vec3 any_perpendicular(const glm::vec3& t) {
  const glm::vec3 h = std::abs(t.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  return glm::normalize(glm::cross(t, h));
}

void add_tube(OutputMesh& m, const Plant& plant, const std::vector<std::int32_t>& chain, const MesherOptions& o) {
  // Points and radii along the chain; a side branch starts at its parent's node with its own radius.
  std::vector<glm::vec3> pts;
  std::vector<float> rad;
  for (std::size_t j = 0; j < chain.size(); ++j) {
    const auto& node = plant.nodes[static_cast<std::size_t>(chain[j])];
    const glm::vec3 p = node.position;
    if (!pts.empty() && glm::length(p - pts.back()) < 1e-7f) continue;  // drop zero-length segments
    // A lateral branch (its first node's shoot differs from the parent's) starts with its own radius.
    float r = node.radius;
    if (j == 0 && chain.size() > 1) {
      const auto& next = plant.nodes[static_cast<std::size_t>(chain[1])];
      if (next.shoot != node.shoot) r = std::min(r, next.radius);
    }
    r = std::max(r, o.min_radius > 0.0f ? o.min_radius : 1e-4f);
    pts.push_back(p);
    rad.push_back(r);
  }
  if (pts.size() < 2) return;
  const int sides = std::clamp(o.sides, 3, 64);
  const auto base = static_cast<std::uint32_t>(m.positions.size());
  glm::vec3 normal(0.0f);
  for (std::size_t j = 0; j < pts.size(); ++j) {
    const glm::vec3 a = pts[j == 0 ? 0 : j - 1], b = pts[j + 1 < pts.size() ? j + 1 : j];
    const glm::vec3 t = glm::normalize(b - a);
    // Parallel transport (projection form): keep the previous normal, made perpendicular to t.
    glm::vec3 nrm = j == 0 ? any_perpendicular(t) : normal - glm::dot(normal, t) * t;
    if (glm::length(nrm) < 1e-6f) nrm = any_perpendicular(t);
    normal = glm::normalize(nrm);
    const glm::vec3 binormal = glm::cross(t, normal);
    for (int s = 0; s < sides; ++s) {
      const float ang = 2.0f * std::numbers::pi_v<float> * static_cast<float>(s) / static_cast<float>(sides);
      const glm::vec3 d = std::cos(ang) * normal + std::sin(ang) * binormal;
      m.positions.push_back(pts[j] + rad[j] * d);
      m.normals.push_back(d);
    }
  }
  const auto S = static_cast<std::uint32_t>(sides);
  for (std::uint32_t j = 0; j + 1 < pts.size(); ++j) {
    for (std::uint32_t s = 0; s < S; ++s) {
      const std::uint32_t a = base + j * S + s, b = base + j * S + (s + 1) % S;
      const std::uint32_t c = a + S, d = b + S;
      m.triangles.emplace_back(a, b, d);
      m.triangles.emplace_back(a, d, c);
    }
  }
  if (o.caps) {
    for (const bool start : {true, false}) {
      const std::size_t j = start ? 0 : pts.size() - 1;
      const glm::vec3 t = glm::normalize(pts[start ? 1 : j] - pts[start ? 0 : j - 1]);
      const auto centre = static_cast<std::uint32_t>(m.positions.size());
      m.positions.push_back(pts[j]);
      m.normals.push_back(start ? -t : t);
      const std::uint32_t ring = base + static_cast<std::uint32_t>(j) * S;
      for (std::uint32_t s = 0; s < S; ++s) {
        const std::uint32_t a = ring + s, b = ring + (s + 1) % S;
        if (start)
          m.triangles.emplace_back(centre, b, a);
        else
          m.triangles.emplace_back(centre, a, b);
      }
    }
  }
}

void add_organ(OutputMesh& m, const Organ& organ, const OrganShape& shape, const glm::vec3* color) {
  const auto base = static_cast<std::uint32_t>(m.positions.size());
  const glm::mat3 r = glm::mat3_cast(organ.orientation);
  for (std::size_t k = 0; k < shape.mesh.vertices.size(); ++k) {
    // organ_point's arithmetic in its order (the same floats), with the rotation made once per organ.
    m.positions.push_back(organ.position + r * (shape.mesh.vertices[k] * organ.size));
    m.normals.push_back(r * shape.normals[k]);
  }
  if (color) m.colors.resize(m.positions.size(), *color);
  for (const auto& t : shape.mesh.triangles) m.triangles.push_back(t + glm::uvec3(base));
}

}  // namespace

MesherOptions with_leaf_mesh(MesherOptions o) {
  if (!o.leaf_obj.empty() && !o.leaf) o.leaf = std::make_shared<const OrganShape>(load_organ_obj(o.leaf_obj));
  return o;
}

OrganShapes organ_shapes(const Plant& plant, const MesherOptions& o) {
  return OrganShapes(plant, o.leaf.get());
}

glm::vec3 material_srgb(std::string_view material) {
  if (material == "bark") return {0.40f, 0.27f, 0.17f};
  if (material == "flower") return organ_kind_srgb(OrganKind::Flower);
  return organ_kind_srgb(OrganKind::Leaf);
}

OutputMesh mesh_plant(const Plant& plant, const MesherOptions& o) {
  OutputMesh m;
  const OrganShapes shapes = organ_shapes(plant, o);
  // Vertex colours only when some organ has a colour of its own; then every vertex has one, its organ's
  // or its group's material colour.
  const bool colored = shapes.any_color(plant);
  auto organ_mesh = [&](const Organ& organ) {
    if (!colored) return add_organ(m, organ, shapes.of(organ), nullptr);
    const glm::vec3 c = shapes.linear_color(organ);
    add_organ(m, organ, shapes.of(organ), &c);
  };
  auto group = [&](const char* name, const char* material, auto&& body) {
    const auto first = static_cast<std::uint32_t>(m.triangles.size());
    body();
    if (colored) m.colors.resize(m.positions.size(), srgb_to_linear(material_srgb(material)));
    const auto count = static_cast<std::uint32_t>(m.triangles.size()) - first;
    if (count > 0) m.groups.push_back({name, material, first, count});
  };
  group("branches", "bark", [&] {
    for (const auto& chain : plant_chains(plant)) add_tube(m, plant, chain, o);
  });
  group("leaves", "leaf", [&] {
    for (const auto& organ : plant.organs)
      if (organ.kind == OrganKind::Leaf || organ.kind == OrganKind::YoungLeaf) organ_mesh(organ);
  });
  group("flowers", "flower", [&] {
    for (const auto& organ : plant.organs)
      if (organ.kind == OrganKind::Flower || organ.kind == OrganKind::Bud) organ_mesh(organ);
  });
  group("polygons", "leaf", [&] {
    for (const auto& poly : plant.polygons) {
      if (poly.vertices.size() < 3) continue;
      const auto base = static_cast<std::uint32_t>(m.positions.size());
      glm::vec3 n(0.0f);  // Newell normal
      for (std::size_t i = 0; i < poly.vertices.size(); ++i) {
        const glm::vec3 a = poly.vertices[i], b = poly.vertices[(i + 1) % poly.vertices.size()];
        n += glm::vec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
      }
      n = glm::length(n) > 0.0f ? glm::normalize(n) : glm::vec3(0, 1, 0);
      for (const auto& v : poly.vertices) {
        m.positions.push_back(v);
        m.normals.push_back(n);
      }
      for (std::uint32_t i = 1; i + 1 < poly.vertices.size(); ++i)
        m.triangles.emplace_back(base, base + i, base + i + 1);
    }
  });
  return m;
}

}  // namespace growbench
