#include "scenes/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

namespace growbench::geom {

glm::vec3 closest_point_on_triangle(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b,
                                    const glm::vec3& c) {
  const glm::vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return a;
  const glm::vec3 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return a + ab * (d1 / (d1 - d3));
  const glm::vec3 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const float denom = 1.0f / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

TriangleMesh make_box(const std::string& name, const glm::vec3& lo, const glm::vec3& hi) {
  TriangleMesh m;
  m.name = name;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
  // Outward-facing (counter-clockwise seen from outside).
  const unsigned f[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                            {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : f) {
    m.triangles.emplace_back(q[0], q[1], q[2]);
    m.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return m;
}

TriangleMesh make_cylinder(const std::string& name, const glm::vec3& base, const glm::vec3& top,
                           float r0, float r1, int sides) {
  TriangleMesh m;
  m.name = name;
  const glm::vec3 axis = glm::normalize(top - base);
  const glm::vec3 helper = std::abs(axis.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  const glm::vec3 u = glm::normalize(glm::cross(axis, helper));
  const glm::vec3 v = glm::cross(axis, u);
  for (int i = 0; i < sides; ++i) {
    const float a = 2.0f * std::numbers::pi_v<float> * static_cast<float>(i) / static_cast<float>(sides);
    const glm::vec3 d = std::cos(a) * u + std::sin(a) * v;
    m.vertices.push_back(base + r0 * d);
    m.vertices.push_back(top + r1 * d);
  }
  const auto cb = static_cast<unsigned>(m.vertices.size());
  m.vertices.push_back(base);
  m.vertices.push_back(top);
  const auto n = static_cast<unsigned>(sides);
  for (unsigned i = 0; i < n; ++i) {
    const unsigned j = (i + 1) % n;
    const unsigned b0 = 2 * i, t0 = 2 * i + 1, b1 = 2 * j, t1 = 2 * j + 1;
    // (u, v, axis) is right-handed, so increasing angle runs counter-clockwise seen from the top.
    m.triangles.emplace_back(b0, b1, t1);
    m.triangles.emplace_back(b0, t1, t0);
    m.triangles.emplace_back(cb, b1, b0);
    m.triangles.emplace_back(cb + 1, t0, t1);
  }
  return m;
}

TriangleMesh make_icosphere(const std::string& name, const glm::vec3& center, float radius,
                            int subdivisions) {
  TriangleMesh m;
  m.name = name;
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                              {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                              {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p = glm::normalize(p);
  std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                               {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                               {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                               {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<unsigned, unsigned>, unsigned> mid;
    auto midpoint = [&](unsigned a, unsigned b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(glm::normalize(v[a] + v[b]));
      const auto idx = static_cast<unsigned>(v.size() - 1);
      mid.emplace(key, idx);
      return idx;
    };
    std::vector<glm::uvec3> nf;
    nf.reserve(f.size() * 4);
    for (const auto& tri : f) {
      const unsigned a = midpoint(tri.x, tri.y), b = midpoint(tri.y, tri.z), c = midpoint(tri.z, tri.x);
      nf.emplace_back(tri.x, a, c);
      nf.emplace_back(tri.y, b, a);
      nf.emplace_back(tri.z, c, b);
      nf.emplace_back(a, b, c);
    }
    f.swap(nf);
  }
  m.vertices.reserve(v.size());
  for (const auto& p : v) m.vertices.push_back(center + radius * p);
  m.triangles = std::move(f);
  return m;
}

std::vector<glm::vec3> vertex_normal_sums(const TriangleMesh& m) {
  std::vector<glm::vec3> n(m.vertices.size(), glm::vec3(0.0f));
  for (const auto& t : m.triangles) {
    const glm::vec3 f = glm::cross(m.vertices[t.y] - m.vertices[t.x], m.vertices[t.z] - m.vertices[t.x]);
    n[t.x] += f;
    n[t.y] += f;
    n[t.z] += f;
  }
  return n;
}

bool fill_small_holes(TriangleMesh& m, double max_boundary_fraction) {
  if (m.is_closed()) return true;
  std::map<std::pair<unsigned, unsigned>, int> directed;
  for (const auto& t : m.triangles)
    for (int i = 0; i < 3; ++i) ++directed[{t[i], t[(i + 1) % 3]}];
  std::map<unsigned, unsigned> next;  // boundary edge a -> b (its reverse b -> a is missing)
  for (const auto& [e, n] : directed) {
    if (n != 1) return false;  // a repeated directed edge: not orientable as given
    if (directed.count({e.second, e.first})) continue;
    if (!next.emplace(e.first, e.second).second) return false;  // two boundary edges leave one vertex
  }
  if (static_cast<double>(next.size()) > max_boundary_fraction * static_cast<double>(directed.size())) return false;
  TriangleMesh filled = m;
  std::map<unsigned, bool> used;
  for (const auto& [start, unused] : next) {
    if (used[start]) continue;
    std::vector<unsigned> loop;
    for (unsigned v = start; !used[v];) {
      used[v] = true;
      loop.push_back(v);
      const auto it = next.find(v);
      if (it == next.end()) return false;
      v = it->second;
      if (v != start && used[v]) return false;  // a figure-eight boundary
    }
    glm::dvec3 c(0.0);
    for (const auto v : loop) c += glm::dvec3(m.vertices[v]);
    const auto centre = static_cast<unsigned>(filled.vertices.size());
    filled.vertices.emplace_back(c / static_cast<double>(loop.size()));
    for (std::size_t i = 0; i < loop.size(); ++i) filled.triangles.emplace_back(centre, loop[(i + 1) % loop.size()], loop[i]);
  }
  if (!filled.is_closed()) return false;
  m = std::move(filled);
  return true;
}

glm::mat4 trs(const glm::vec3& translate, const glm::vec3& rotate_deg, const glm::vec3& scale) {
  glm::mat4 m = glm::translate(glm::mat4(1.0f), translate);
  // Rotation order: Y (yaw), then X, then Z, applied to the scaled object.
  m = glm::rotate(m, glm::radians(rotate_deg.y), glm::vec3(0, 1, 0));
  m = glm::rotate(m, glm::radians(rotate_deg.x), glm::vec3(1, 0, 0));
  m = glm::rotate(m, glm::radians(rotate_deg.z), glm::vec3(0, 0, 1));
  return glm::scale(m, scale);
}

}  // namespace growbench::geom
