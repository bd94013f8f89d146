#include "scenes/scene.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_map>

#include <fmt/format.h>
#include <xxhash.h>

namespace growbench {

Aabb TriangleMesh::bounds() const {
  Aabb b;
  for (const auto& v : vertices) b.extend(v);
  return b;
}

double TriangleMesh::area() const {
  double a = 0.0;
  for (const auto& t : triangles)
    a += 0.5 * glm::length(glm::cross(vertices[t.y] - vertices[t.x], vertices[t.z] - vertices[t.x]));
  return a;
}

bool TriangleMesh::is_closed() const {
  if (triangles.empty()) return false;
  // Directed edge a->b must meet exactly one b->a.
  std::unordered_map<std::uint64_t, int> count;
  count.reserve(triangles.size() * 3);
  auto key = [](std::uint32_t a, std::uint32_t b) { return (std::uint64_t{a} << 32) | b; };
  for (const auto& t : triangles) {
    const std::uint32_t v[3] = {t.x, t.y, t.z};
    for (int i = 0; i < 3; ++i) ++count[key(v[i], v[(i + 1) % 3])];
  }
  for (const auto& [k, n] : count) {
    if (n != 1) return false;
    const auto a = static_cast<std::uint32_t>(k >> 32), b = static_cast<std::uint32_t>(k);
    auto it = count.find(key(b, a));
    if (it == count.end() || it->second != 1) return false;
  }
  return true;
}

void TriangleMesh::append(const TriangleMesh& other) {
  // Texture coordinates survive only when both parts have them: a half-mapped mesh has no mapping.
  const bool uv = (triangles.empty() || has_uvs()) && other.has_uvs();
  if (!uv) {
    uvs.clear();
    uv_triangles.clear();
  } else {
    const auto uv_base = static_cast<unsigned>(uvs.size());
    uvs.insert(uvs.end(), other.uvs.begin(), other.uvs.end());
    for (const auto& t : other.uv_triangles) uv_triangles.emplace_back(t + glm::uvec3(uv_base));
  }
  const auto base = static_cast<unsigned>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const auto& t : other.triangles) triangles.emplace_back(t + glm::uvec3(base));
}

void TriangleMesh::transform(const glm::mat4& m) {
  for (auto& v : vertices) v = glm::vec3(m * glm::vec4(v, 1.0f));
  // A mirroring transform flips orientation: swap winding to keep faces outward.
  if (glm::determinant(glm::mat3(m)) < 0.0f) {
    for (auto& t : triangles) std::swap(t.y, t.z);
    for (auto& t : uv_triangles) std::swap(t.y, t.z);
  }
}

Aabb Shape::bounds() const {
  Aabb b;
  switch (kind) {
    case Kind::Box:
      b.extend(min);
      b.extend(max);
      break;
    case Kind::Sphere:
      b.extend(center - radii);
      b.extend(center + radii);
      break;
    case Kind::Mesh:
      b = mesh.bounds();
      break;
  }
  return b;
}

double Shape::volume() const {
  switch (kind) {
    case Kind::Box: {
      const glm::vec3 s = glm::max(max - min, glm::vec3(0.0f));
      return double(s.x) * s.y * s.z;
    }
    case Kind::Sphere:
      return 4.0 / 3.0 * std::numbers::pi * radii.x * radii.y * radii.z;
    case Kind::Mesh: {
      double v = 0.0;
      for (const auto& t : mesh.triangles)
        v += glm::dot(glm::dvec3(mesh.vertices[t.x]),
                      glm::cross(glm::dvec3(mesh.vertices[t.y]), glm::dvec3(mesh.vertices[t.z])));
      return std::abs(v) / 6.0;
    }
  }
  return 0.0;
}

bool Shape::contains_analytic(const glm::vec3& p) const {
  switch (kind) {
    case Kind::Box:
      return Aabb{min, max}.contains(p);
    case Kind::Sphere: {
      const glm::vec3 q = (p - center) / radii;
      return glm::dot(q, q) <= 1.0f;
    }
    case Kind::Mesh:
      return false;
  }
  return false;
}

Aabb Scene::bounds() const {
  Aabb b;
  for (const auto& m : meshes) b.extend(m.bounds());
  if (envelope) b.extend(envelope->bounds());
  for (const auto& s : seeds) b.extend(s.position);
  return b;
}

std::string Scene::out_of_bounds() const {
  const auto far = [](const glm::vec3& p) {
    return !(glm::all(glm::lessThanEqual(glm::abs(p), glm::vec3(kMaxCoordinate))));  // NaN is far too
  };
  const auto at = [](const glm::vec3& p) { return fmt::format("({}, {}, {})", p.x, p.y, p.z); };
  for (const auto& m : meshes)
    for (std::size_t i = 0; i < m.vertices.size(); ++i)
      if (far(m.vertices[i])) return fmt::format("mesh '{}' vertex {} at {}", m.name, i + 1, at(m.vertices[i]));
  for (std::size_t i = 0; i < seeds.size(); ++i)
    if (far(seeds[i].position)) return fmt::format("seed {} at {}", i + 1, at(seeds[i].position));
  if (light.kind == Light::Kind::Point && far(light.position))
    return fmt::format("the point light at {}", at(light.position));
  if (envelope && (far(envelope->bounds().min) || far(envelope->bounds().max))) return "the envelope";
  for (std::size_t i = 0; i < zones.size(); ++i)
    if (far(zones[i].shape.bounds().min) || far(zones[i].shape.bounds().max)) return fmt::format("zone {}", i + 1);
  if (far(camera.position) || far(camera.look_at)) return "the camera";
  return "";
}

bool Scene::has_climbable() const {
  for (const auto& m : meshes)
    if (m.climbable) return true;
  return false;
}

std::size_t Scene::triangle_count() const {
  std::size_t n = 0;
  for (const auto& m : meshes) n += m.triangles.size();
  return n;
}

namespace {
struct Hasher {
  XXH3_state_t* st = XXH3_createState();
  Hasher() { XXH3_64bits_reset(st); }
  ~Hasher() { XXH3_freeState(st); }
  Hasher(const Hasher&) = delete;
  Hasher& operator=(const Hasher&) = delete;
  void bytes(const void* p, std::size_t n) { XXH3_64bits_update(st, p, n); }
  template <class T>
  void pod(const T& v) {
    bytes(&v, sizeof(T));
  }
  void str(const std::string& s) {
    pod(s.size());
    bytes(s.data(), s.size());
  }
  void mesh(const TriangleMesh& m) {
    str(m.name);
    pod(m.climbable);
    if (!m.visible) str("collision-only");  // only then, so every other mesh keeps the hash it always had
    pod(m.vertices.size());
    bytes(m.vertices.data(), m.vertices.size() * sizeof(glm::vec3));
    pod(m.triangles.size());
    bytes(m.triangles.data(), m.triangles.size() * sizeof(glm::uvec3));
    // Texture coordinates only when present, so a mesh without them keeps the hash it always had.
    if (m.has_uvs()) {
      pod(m.uvs.size());
      bytes(m.uvs.data(), m.uvs.size() * sizeof(glm::vec2));
      bytes(m.uv_triangles.data(), m.uv_triangles.size() * sizeof(glm::uvec3));
    }
  }
  void shape(const Shape& s) {
    pod(s.kind);
    pod(s.min);
    pod(s.max);
    pod(s.center);
    pod(s.radii);
    mesh(s.mesh);
  }
};
}  // namespace

std::string Scene::content_hash() const {
  Hasher h;
  h.pod(meshes.size());
  for (const auto& m : meshes) h.mesh(m);
  h.pod(seeds.size());
  for (const auto& s : seeds) {
    h.pod(s.position);
    h.pod(s.direction);
    h.pod(s.start_step);
  }
  h.pod(light.kind);
  h.pod(light.direction);
  h.pod(light.position);
  h.pod(envelope.has_value());
  if (envelope) h.shape(*envelope);
  h.pod(zones.size());
  for (const auto& z : zones) {
    h.pod(z.kind);
    h.pod(z.strength);
    h.shape(z.shape);
  }
  h.pod(camera.position);
  h.pod(camera.look_at);
  h.pod(camera.fov_deg);
  return fmt::format("{:016x}", XXH3_64bits_digest(h.st));
}

}  // namespace growbench
