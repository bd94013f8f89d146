#include "scenes/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

namespace growbench::geom {

namespace {
template <class V>
std::pair<V, TriangleFeature> closest_feature(const V& p, const V& a, const V& b, const V& c) {
  using F = TriangleFeature;
  using T = typename V::value_type;
  const V ab = b - a, ac = c - a, ap = p - a;
  const T d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= T(0) && d2 <= T(0)) return {a, F::VertexA};
  const V bp = p - b;
  const T d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= T(0) && d4 <= d3) return {b, F::VertexB};
  const T vc = d1 * d4 - d3 * d2;
  if (vc <= T(0) && d1 >= T(0) && d3 <= T(0)) return {a + ab * (d1 / (d1 - d3)), F::EdgeAB};
  const V cp = p - c;
  const T d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= T(0) && d5 <= d6) return {c, F::VertexC};
  const T vb = d5 * d2 - d1 * d6;
  if (vb <= T(0) && d2 >= T(0) && d6 <= T(0)) return {a + ac * (d2 / (d2 - d6)), F::EdgeCA};
  const T va = d3 * d6 - d5 * d4;
  if (va <= T(0) && (d4 - d3) >= T(0) && (d5 - d6) >= T(0))
    return {b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), F::EdgeBC};
  const T denom = T(1) / (va + vb + vc);
  return {a + ab * (vb * denom) + ac * (vc * denom), F::Face};
}
}  // namespace

TriangleFeaturePoint closest_feature_on_triangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                                 const glm::dvec3& c) {
  const auto [q, f] = closest_feature(p, a, b, c);
  return {q, f};
}

glm::vec3 closest_point_on_triangle(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  return closest_feature(p, a, b, c).first;
}

float segment_distance(const glm::vec3& p1, const glm::vec3& q1, const glm::vec3& p2, const glm::vec3& q2) {
  const glm::vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const float a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
  float s = 0.0f, t = 0.0f;
  constexpr float eps = 1e-12f;
  if (a <= eps && e <= eps) return glm::length(r);
  if (a <= eps) {
    t = std::clamp(f / e, 0.0f, 1.0f);
  } else {
    const float c = glm::dot(d1, r);
    if (e <= eps) {
      s = std::clamp(-c / a, 0.0f, 1.0f);
    } else {
      const float b = glm::dot(d1, d2), denom = a * e - b * b;
      s = denom > eps ? std::clamp((b * f - c * e) / denom, 0.0f, 1.0f) : 0.0f;
      t = (b * s + f) / e;
      if (t < 0.0f) {
        t = 0.0f;
        s = std::clamp(-c / a, 0.0f, 1.0f);
      } else if (t > 1.0f) {
        t = 1.0f;
        s = std::clamp((b - c) / a, 0.0f, 1.0f);
      }
    }
  }
  return glm::length((p1 + d1 * s) - (p2 + d2 * t));
}

float segment_triangle_distance(const glm::vec3& p, const glm::vec3& q, const glm::vec3 (&t)[3]) {
  // Where the segment crosses the triangle's plane, the crossing in the triangle (by the signs of the
  // sub-triangles' normals against the plane's) is a meeting.
  const glm::vec3 n = glm::cross(t[1] - t[0], t[2] - t[0]);
  const float dp = glm::dot(n, p - t[0]), dq = glm::dot(n, q - t[0]);
  if ((dp <= 0.0f && dq >= 0.0f) || (dp >= 0.0f && dq <= 0.0f)) {
    if (dp != dq) {
      const glm::vec3 x = p + (dp / (dp - dq)) * (q - p);
      bool inside = glm::dot(n, n) > 0.0f;
      for (int k = 0; k < 3 && inside; ++k) inside = glm::dot(n, glm::cross(t[(k + 1) % 3] - t[k], x - t[k])) >= 0.0f;
      if (inside) return 0.0f;
    }
  }
  float d = std::min(glm::length(p - closest_point_on_triangle(p, t[0], t[1], t[2])),
                     glm::length(q - closest_point_on_triangle(q, t[0], t[1], t[2])));
  for (int k = 0; k < 3; ++k) d = std::min(d, segment_distance(p, q, t[k], t[(k + 1) % 3]));
  return d;
}

namespace {

// The interval that triangle t covers on the line (point o, direction d) where its plane meets the
// other's: dist holds t's signed distances to the other plane (not all zero, not all on one side). The
// line crosses the two edges from the vertex alone on its side (Moller 1997).
std::pair<double, double> line_interval(const glm::dvec3 t[3], const glm::dvec3& dist, const glm::dvec3& o,
                                        const glm::dvec3& d) {
  int lone = 2;
  if (dist[0] * dist[1] > 0)
    lone = 2;
  else if (dist[0] * dist[2] > 0)
    lone = 1;
  else if (dist[1] * dist[2] > 0 || dist[0] != 0)
    lone = 0;
  else if (dist[1] != 0)
    lone = 1;
  auto cross_at = [&](int other) {  // never divides by zero: dist[lone] and dist[other] differ in sign or one is 0
    const double s = dist[lone] / (dist[lone] - dist[other]);
    return glm::dot(t[lone] + s * (t[other] - t[lone]) - o, d);
  };
  double a = cross_at((lone + 1) % 3), b = cross_at((lone + 2) % 3);
  if (a > b) std::swap(a, b);
  return {a, b};
}

// Area of the part of triangle a inside triangle b, both in one plane (a clipped by b's three edges).
double overlap_area_2d(const glm::dvec2 (&a)[3], const glm::dvec2 (&b)[3]) {
  auto cross2 = [](const glm::dvec2& u, const glm::dvec2& v) { return u.x * v.y - u.y * v.x; };
  const double orient = cross2(b[1] - b[0], b[2] - b[0]) >= 0.0 ? 1.0 : -1.0;
  std::vector<glm::dvec2> poly(a, a + 3), next;
  for (int e = 0; e < 3 && !poly.empty(); ++e) {
    const glm::dvec2 p = b[e], q = b[(e + 1) % 3];
    auto side = [&](const glm::dvec2& v) { return orient * cross2(q - p, v - p); };
    next.clear();
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const glm::dvec2 u = poly[i], v = poly[(i + 1) % poly.size()];
      const double su = side(u), sv = side(v);
      if (su >= 0.0) next.push_back(u);
      if ((su >= 0.0) != (sv >= 0.0)) next.push_back(u + (v - u) * (su / (su - sv)));
    }
    poly.swap(next);
  }
  double area = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) area += cross2(poly[i], poly[(i + 1) % poly.size()]);
  return 0.5 * std::abs(area);
}

}  // namespace

bool triangles_overlap(const glm::vec3 (&t1)[3], const glm::vec3 (&t2)[3]) {
  const glm::dvec3 a[3] = {t1[0], t1[1], t1[2]}, b[3] = {t2[0], t2[1], t2[2]};
  auto size_of = [](const glm::dvec3(&t)[3]) {
    return std::max({glm::length(t[1] - t[0]), glm::length(t[2] - t[1]), glm::length(t[0] - t[2])});
  };
  const double scale = std::max(size_of(a), size_of(b));
  if (!(scale > 0.0)) return false;
  // Lengths below eps are rounding: a touch, not an overlap. It covers the float rounding of the
  // coordinates (a leaf lying on a wall at 1 m is placed to within about 1e-7 m) and a part per million of
  // the triangles' size, so blades that lie in one plane to that tolerance are tested as coplanar.
  double reach = 0.0;
  for (const auto* t : {&a, &b})
    for (const auto& v : *t) reach = std::max({reach, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  const double eps = 1e-6 * scale + 8.0 * static_cast<double>(std::numeric_limits<float>::epsilon()) * reach;
  glm::dvec3 na = glm::cross(a[1] - a[0], a[2] - a[0]), nb = glm::cross(b[1] - b[0], b[2] - b[0]);
  const double la = glm::length(na), lb = glm::length(nb);
  if (la <= eps * eps || lb <= eps * eps) return false;  // a degenerate triangle has no area to share
  na /= la;
  nb /= lb;
  // Each triangle's vertices against the other's plane; within eps counts as on it.
  auto against = [&](const glm::dvec3(&t)[3], const glm::dvec3& n, const glm::dvec3& o) {
    glm::dvec3 d;
    for (int i = 0; i < 3; ++i) {
      d[i] = glm::dot(n, t[i] - o);
      if (std::abs(d[i]) <= eps) d[i] = 0.0;
    }
    return d;
  };
  const glm::dvec3 da = against(a, nb, b[0]), db = against(b, na, a[0]);
  auto zeros = [](const glm::dvec3& d) { return (d[0] == 0.0) + (d[1] == 0.0) + (d[2] == 0.0); };
  auto one_side = [](const glm::dvec3& d) {
    return (d[0] >= 0 && d[1] >= 0 && d[2] >= 0) || (d[0] <= 0 && d[1] <= 0 && d[2] <= 0);
  };
  if (zeros(da) < 3 && zeros(db) < 3) {
    // A triangle on one side of the other's plane meets it in a vertex at most, or in an edge lying on
    // it. Otherwise both cut the line where the planes meet, and their intervals there must share more
    // than a point.
    if ((one_side(da) && zeros(da) < 2) || (one_side(db) && zeros(db) < 2)) return false;
    const glm::dvec3 c = glm::cross(na, nb);
    if (!(glm::length(c) > 1e-12)) return false;  // parallel planes, apart by more than eps
    const glm::dvec3 d = c / glm::length(c);
    const auto [a0, a1] = line_interval(a, da, a[0], d);
    const auto [b0, b1] = line_interval(b, db, a[0], d);
    return std::min(a1, b1) - std::max(a0, b0) > eps;
  }
  // Coplanar: the area they share, in the plane's dominant projection.
  const glm::dvec3 an = glm::abs(na);
  const int drop = an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
  auto flat = [&](const glm::dvec3& v) {
    return drop == 0 ? glm::dvec2(v.y, v.z) : drop == 1 ? glm::dvec2(v.x, v.z) : glm::dvec2(v.x, v.y);
  };
  const glm::dvec2 pa[3] = {flat(a[0]), flat(a[1]), flat(a[2])}, pb[3] = {flat(b[0]), flat(b[1]), flat(b[2])};
  return overlap_area_2d(pa, pb) > eps * scale;
}

TriangleMesh make_box(const std::string& name, const glm::vec3& lo, const glm::vec3& hi) {
  TriangleMesh m;
  m.name = name;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
  // Outward-facing (counter-clockwise seen from outside).
  const unsigned f[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : f) {
    m.triangles.emplace_back(q[0], q[1], q[2]);
    m.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return m;
}

TriangleMesh make_cylinder(const std::string& name, const glm::vec3& base, const glm::vec3& top, float r0, float r1,
                           int sides) {
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

TriangleMesh make_icosphere(const std::string& name, const glm::vec3& center, float radius, int subdivisions) {
  TriangleMesh m;
  m.name = name;
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p = glm::normalize(p);
  std::vector<glm::uvec3> f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                               {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                               {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
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

namespace {

// Triangulates a hole's loop (in patch order) by ear clipping in the plane of its Newell normal, so a
// flat or gently curved hole gets a patch that does not fold over itself (a fan from the centroid folds
// wherever the loop is not star-shaped around it, and a folded patch has no consistent inside). False
// when the projected loop is not simple enough to clip; the caller then fans it.
bool ear_clip(const std::vector<glm::vec3>& vertices, const std::vector<unsigned>& loop, std::vector<glm::uvec3>& out) {
  const std::size_t n = loop.size();
  if (n < 3) return false;
  glm::dvec3 normal(0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3 a(vertices[loop[i]]), b(vertices[loop[(i + 1) % n]]);
    normal += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
  }
  if (!(glm::length(normal) > 0.0)) return false;
  normal = glm::normalize(normal);
  const glm::dvec3 helper = std::abs(normal.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 u = glm::normalize(glm::cross(normal, helper)), v = glm::cross(normal, u);
  std::vector<glm::dvec2> p(n);
  for (std::size_t i = 0; i < n; ++i)
    p[i] = {glm::dot(glm::dvec3(vertices[loop[i]]), u), glm::dot(glm::dvec3(vertices[loop[i]]), v)};
  auto cross2 = [](const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  };
  std::vector<std::size_t> left(n);
  for (std::size_t i = 0; i < n; ++i) left[i] = i;
  std::vector<glm::uvec3> tris;
  while (left.size() > 3) {
    bool clipped = false;
    for (std::size_t k = 0; k < left.size() && !clipped; ++k) {
      const std::size_t a = left[(k + left.size() - 1) % left.size()], b = left[k], c = left[(k + 1) % left.size()];
      if (cross2(p[a], p[b], p[c]) <= 0.0) continue;  // reflex or flat: not an ear
      bool empty = true;
      for (const auto o : left) {
        if (o == a || o == b || o == c) continue;
        if (cross2(p[a], p[b], p[o]) >= 0.0 && cross2(p[b], p[c], p[o]) >= 0.0 && cross2(p[c], p[a], p[o]) >= 0.0) {
          empty = false;
          break;
        }
      }
      if (!empty) continue;
      tris.emplace_back(loop[a], loop[b], loop[c]);
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(k));
      clipped = true;
    }
    if (!clipped) return false;
  }
  if (cross2(p[left[0]], p[left[1]], p[left[2]]) <= 0.0) return false;
  tris.emplace_back(loop[left[0]], loop[left[1]], loop[left[2]]);
  out.insert(out.end(), tris.begin(), tris.end());
  return true;
}

}  // namespace

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
    // The patch runs against the boundary edges (a -> b is a triangle's, the patch takes b -> a).
    std::reverse(loop.begin(), loop.end());
    if (!ear_clip(m.vertices, loop, filled.triangles)) {
      glm::dvec3 c(0.0);
      for (const auto v : loop) c += glm::dvec3(m.vertices[v]);
      const auto centre = static_cast<unsigned>(filled.vertices.size());
      filled.vertices.emplace_back(c / static_cast<double>(loop.size()));
      for (std::size_t i = 0; i < loop.size(); ++i)
        filled.triangles.emplace_back(centre, loop[i], loop[(i + 1) % loop.size()]);
    }
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

ShadedMesh crease_shaded(const TriangleMesh& m) {
  const std::size_t nv = m.vertices.size(), nt = m.triangles.size();
  std::vector<glm::vec3> face(nt);  // area-weighted normals
  std::vector<std::vector<std::uint32_t>> around(nv);
  for (std::size_t t = 0; t < nt; ++t) {
    const glm::uvec3 tri = m.triangles[t];
    face[t] = glm::cross(m.vertices[tri.y] - m.vertices[tri.x], m.vertices[tri.z] - m.vertices[tri.x]);
    for (int k = 0; k < 3; ++k) around[tri[k]].push_back(static_cast<std::uint32_t>(t));
  }
  const float cos_crease = std::cos(glm::radians(kCreaseDeg));
  ShadedMesh out;
  out.triangles.resize(nt);
  // Per original vertex, the split copies made so far: (new index); a corner reuses a copy whose normal
  // matches its own.
  std::vector<std::vector<std::uint32_t>> copies(nv);
  for (std::size_t t = 0; t < nt; ++t) {
    const float lt = glm::length(face[t]);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = m.triangles[t][k];
      glm::vec3 n(0.0f);
      for (const std::uint32_t f : around[v]) {
        const float lf = glm::length(face[f]);
        if (lf > 0.0f && lt > 0.0f && glm::dot(face[f] / lf, face[t] / lt) >= cos_crease) n += face[f];
      }
      n = glm::length(n) > 0.0f ? glm::normalize(n) : glm::vec3(0.0f, 1.0f, 0.0f);
      std::uint32_t id = UINT32_MAX;
      for (const std::uint32_t c : copies[v])
        if (glm::dot(out.normals[c], n) > 0.9999f) id = c;
      if (id == UINT32_MAX) {
        id = static_cast<std::uint32_t>(out.vertices.size());
        out.vertices.push_back(m.vertices[v]);
        out.normals.push_back(n);
        copies[v].push_back(id);
      }
      out.triangles[t][k] = id;
    }
  }
  return out;
}

}  // namespace growbench::geom
