// Thomas Luft's per-triangle rules for the ivy generator, written once and used by both the Embree
// path (algorithms/ivy/ivy.cpp) and the brute-force reference in the tests, so the two can only differ
// in *which* triangles they look at, never in what a triangle does.
//
//  * Adhesion: a triangle counts when the point is on its front side and the point's projection onto
//    its plane falls inside it (face interiors only; edges and vertices of neighbouring faces never
//    attract). The closest such triangle within the adhesion distance wins; equal distances go to the
//    lower triangle index, which is what Luft's strict `<` over his triangle loop does.
//  * Collision: the segment from the old position to the candidate crosses a triangle's plane at t in
//    [0, 1], the crossing point is inside the triangle, and the segment enters from the front
//    (n . d < 0). The candidate is mirrored across that plane and the loop goes on with the mirrored
//    candidate; whole passes over the triangles repeat while anything was mirrored, and a root whose
//    collision needs a seventh pass dies (Luft's `deadlockCounter++ > 5`).
//
// "Inside" is a barycentric test in double precision with a tolerance of 1e-6 (Luft compared summed
// sub-triangle areas with a tolerance); the tolerance closes the cracks along shared edges that an
// exact test would leave for a segment crossing exactly on an edge.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "core/random.hpp"
#include "scenes/scene.hpp"

namespace growbench::ivy {

// One cache line each: a query touches a handful of triangles scattered over a table of megabytes,
// so every triangle costs a miss, and a record straddling two lines costs two (the bounds, which
// were stored as well, are six min/max operations away).
struct alignas(64) Triangle {
  glm::vec3 a{0.0f}, b{0.0f}, c{0.0f};
  glm::vec3 n{0.0f};     // unit normal of (b - a) x (c - a); zero when degenerate
  bool adhesive = true;  // on a climbable mesh (only those attract)
  [[nodiscard]] glm::vec3 lo() const { return glm::min(a, glm::min(b, c)); }
  [[nodiscard]] glm::vec3 hi() const { return glm::max(a, glm::max(b, c)); }
};
static_assert(sizeof(Triangle) == 64);

// Every triangle of the scene in Luft's loop order: mesh by mesh, triangle by triangle.
struct TriangleTable {
  std::vector<Triangle> tris;
  std::vector<std::uint32_t> offset;  // first id of each mesh

  explicit TriangleTable(const Scene& scene) {
    bool any_climbable = false;
    for (const auto& m : scene.meshes) any_climbable = any_climbable || m.climbable;
    for (const auto& m : scene.meshes) {
      offset.push_back(static_cast<std::uint32_t>(tris.size()));
      for (const auto& t : m.triangles) {
        Triangle r;
        r.a = m.vertices[t.x];
        r.b = m.vertices[t.y];
        r.c = m.vertices[t.z];
        const glm::vec3 n = glm::cross(r.b - r.a, r.c - r.a);
        const float len = glm::length(n);
        r.n = len > 0.0f ? n / len : glm::vec3(0.0f);
        r.adhesive = m.climbable || !any_climbable;
        tris.push_back(r);
      }
    }
  }
  [[nodiscard]] std::uint32_t id(std::uint32_t mesh, std::uint32_t triangle) const { return offset[mesh] + triangle; }
  [[nodiscard]] std::size_t size() const { return tris.size(); }
};

constexpr double kInsideTolerance = 1e-6;

// Squared distance from p to t's bounding box (0 inside it).
inline float box_distance2(const Triangle& t, const glm::vec3& p) {
  const glm::vec3 out = glm::max(glm::vec3(0.0f), glm::max(t.lo() - p, p - t.hi()));
  return glm::dot(out, out);
}

// Whether p (on or near t's plane) lies inside t, by barycentric coordinates.
inline bool inside(const Triangle& t, const glm::vec3& p) {
  const glm::dvec3 a(t.a), v0 = glm::dvec3(t.b) - a, v1 = glm::dvec3(t.c) - a, v2 = glm::dvec3(p) - a;
  const double d00 = glm::dot(v0, v0), d01 = glm::dot(v0, v1), d11 = glm::dot(v1, v1);
  const double d20 = glm::dot(v2, v0), d21 = glm::dot(v2, v1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 0.0)) return false;
  const double v = (d11 * d20 - d01 * d21) / den;
  const double w = (d00 * d21 - d01 * d20) / den;
  return v >= -kInsideTolerance && w >= -kInsideTolerance && 1.0 - v - w >= -kInsideTolerance;
}

// Luft's adhesion rule: the distance from p to t's plane when p is on the front side and its foot
// (returned) is inside t; a negative value when t does not count.
inline float adhesion_distance(const Triangle& t, const glm::vec3& p, glm::vec3& foot) {
  const float nq = glm::dot(t.n, p - t.a);
  if (nq < 0.0f) return -1.0f;
  foot = p - t.n * nq;
  if (!inside(t, foot)) return -1.0f;
  return glm::length(foot - p);
}

// Luft's collision rule for the segment o -> q.
inline bool crosses(const Triangle& t, const glm::vec3& o, const glm::vec3& q) {
  const glm::vec3 d = q - o;
  const float den = glm::dot(t.n, d);
  if (!(den < 0.0f)) return false;  // leaving, parallel or degenerate
  const float t0 = -glm::dot(t.n, o - t.a) / den;
  if (!(t0 >= 0.0f && t0 <= 1.0f)) return false;
  return inside(t, o + d * t0);
}

// p mirrored across t's plane.
inline glm::vec3 mirror(const Triangle& t, const glm::vec3& p) {
  return p - 2.0f * t.n * glm::dot(t.n, p - t.a);
}

struct CollisionResult {
  bool climbing = false;  // something was mirrored
  bool alive = true;      // false: the seventh pass was needed (Luft lets the root die)
  int reflections = 0;
};

// Luft's collision loop over `ids` (ascending triangle ids: his loop order); moves q.
inline CollisionResult collide(const TriangleTable& table, std::span<const std::uint32_t> ids, const glm::vec3& o,
                               glm::vec3& q) {
  CollisionResult r;
  int passes = 0;
  bool mirrored = false;
  do {
    mirrored = false;
    for (const std::uint32_t id : ids) {
      const Triangle& t = table.tris[id];
      if (crosses(t, o, q)) {
        q = mirror(t, q);
        mirrored = true;
        r.climbing = true;
        ++r.reflections;
      }
    }
    if (passes++ > 5) {
      r.alive = false;
      return r;
    }
  } while (mirrored);
  return r;
}

// The running choice of the adhesion target: the lowest (distance, id) among the triangles offered
// that count and lie within `max_distance`. `luft` selects Luft's rule; otherwise the true closest
// point on the triangle (edges and vertices included, either side), as Blender's BVH find_nearest.
struct AdhesionSearch {
  glm::vec3 p{0.0f};
  float max_distance = 0.0f;
  bool luft = true;
  float best = std::numeric_limits<float>::infinity();
  std::uint32_t best_id = std::numeric_limits<std::uint32_t>::max();
  glm::vec3 foot{0.0f};

  bool offer(const Triangle& t, std::uint32_t id,
             glm::vec3 (*closest)(const glm::vec3&, const glm::vec3&, const glm::vec3&, const glm::vec3&)) {
    if (!t.adhesive) return false;
    // Cheap rejections first. They only drop triangles that are farther than the best so far by more
    // than rounding, so the outcome never depends on the order triangles are offered in. The slack is
    // absolute as well as relative: d is measured between float points whose coordinates are rounded
    // at the scale of |p|, so a plane distance (nq) or box distance can exceed the d computed for the
    // same triangle by a few ulps of |p|, which near a surface is far more than 1e-5 of d (a bunny
    // node 3 mm from two faces had nq - d = 4e-8 = 1.4e-5 d, and a relative slack alone let the
    // triangle offered first win). Nothing at or beyond max_distance counts either.
    const float bound = reject_beyond();
    if (box_distance2(t, p) > bound * bound) return false;
    glm::vec3 f;
    float d;
    if (luft) {
      const float nq = glm::dot(t.n, p - t.a);
      if (nq < 0.0f || nq > bound) return false;
      d = adhesion_distance(t, p, f);
      if (d < 0.0f) return false;
    } else {
      f = closest(p, t.a, t.b, t.c);
      d = glm::length(f - p);
    }
    if (!(d < max_distance)) return false;
    if (d < best || (d == best && id < best_id)) {
      best = d;
      best_id = id;
      foot = f;
      return true;
    }
    return false;
  }
  // The distance past which offered triangles are rejected unseen: the best so far (or the maximum)
  // plus rounding slack. A search that offered every triangle this close to p has found Luft's target.
  [[nodiscard]] float reject_beyond() const {
    const float scale = std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z)));
    const float base = std::min(best, max_distance);
    return base * (1.0f + 1e-5f) + 1e-6f * (scale + base);
  }
  // normalize(foot - p) * (1 - d / max_distance); zero when nothing counted or p is on the surface.
  [[nodiscard]] glm::vec3 vector() const {
    if (best_id == std::numeric_limits<std::uint32_t>::max() || !(best > 0.0f)) return glm::vec3(0.0f);
    return glm::normalize(foot - p) * (1.0f - best / max_distance);
  }
};

// Luft's branching weight of a node at relative arc length x: 0 at both ends, 1 mid-root.
inline float branch_weight(float x) {
  return 1.0f - (std::cos(x * 2.0f * std::numbers::pi_v<float>) * 0.5f + 0.5f);
}

// Failures before the first success of Bernoulli(p) trials.
inline std::size_t geometric(Rng& rng, double p) {
  if (p >= 1.0) return 0;
  const double u = 1.0 - rng.uniform();  // (0, 1]
  const double g = std::floor(std::log(u) / std::log1p(-p));
  return g > 1e15 ? static_cast<std::size_t>(1e15) : static_cast<std::size_t>(g);
}

// Where a root of n nodes branches this iteration, or -1: distributed as the first success of Luft's
// loop `for each node k: if (rand * branch_weight(l_k / L) > b) branch at k`, with l_k = length(k)
// non-decreasing and L = length(n - 1), but without visiting every node. Only nodes with w > b can
// succeed; they form the window x in (x0, 1 - x0), w(x0) = b, found by binary search. Inside it,
// candidates are drawn with the maximum probability 1 - b (geometric gaps) and accepted with
// p_k / (1 - b), p_k = 1 - b / w_k: thinning keeps each node's success independent with p_k.
template <class Length>
std::ptrdiff_t sample_branch_node(std::size_t n, Length&& length, float b, Rng& rng) {
  if (n < 2 || b >= 1.0f) return -1;
  const float L = length(n - 1);
  if (!(L > 0.0f)) return -1;
  const double x0 = std::acos(std::clamp(1.0 - 2.0 * std::max(0.0f, b), -1.0, 1.0)) / (2.0 * std::numbers::pi);
  auto first_beyond = [&](double l) {  // first k >= 1 with length(k) > l
    std::size_t lo = 1, hi = n;
    while (lo < hi) {
      const std::size_t mid = (lo + hi) / 2;
      if (static_cast<double>(length(mid)) > l)
        hi = mid;
      else
        lo = mid + 1;
    }
    return lo;
  };
  // One node either side of the analytic window: rounding may put a node with w > b just outside it.
  const std::size_t begin = std::max<std::size_t>(1, first_beyond(x0 * L) - 1);
  const std::size_t end = std::min(n, first_beyond((1.0 - x0) * L) + 1);
  const double pmax = 1.0 - std::max(0.0f, b);
  for (std::size_t k = begin + geometric(rng, pmax); k < end; k += 1 + geometric(rng, pmax)) {
    const float w = branch_weight(length(k) / L);
    const double p = w > b ? 1.0 - static_cast<double>(b) / w : 0.0;
    if (rng.uniform() * pmax < p) return static_cast<std::ptrdiff_t>(k);
  }
  return -1;
}

}  // namespace growbench::ivy
