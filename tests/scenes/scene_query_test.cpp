#include "scenes/scene_query.hpp"

#include <array>

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include "core/errors.hpp"
#include "core/random.hpp"
#include "scenes/geometry.hpp"
#include "scenes/scene_library.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

using test::scene_with;

// Brute force over every triangle, in double precision: the reference for Embree's closest point.
float brute_distance(const Scene& s, const glm::vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& m : s.meshes)
    for (const auto& t : m.triangles) {
      const auto c = geom::closest_feature_on_triangle(glm::dvec3(p), glm::dvec3(m.vertices[t.x]),
                                                       glm::dvec3(m.vertices[t.y]), glm::dvec3(m.vertices[t.z]));
      best = std::min(best, glm::length(c.point - glm::dvec3(p)));
    }
  return static_cast<float>(best);
}

// Brute-force ray parity: the reference for inside tests.
bool brute_inside(const TriangleMesh& m, const glm::vec3& p) {
  const glm::vec3 d = glm::normalize(glm::vec3(0.31f, 0.77f, 0.55f));
  int n = 0;
  for (const auto& t : m.triangles) {
    const glm::vec3 a = m.vertices[t.x], b = m.vertices[t.y], c = m.vertices[t.z];
    const glm::vec3 e1 = b - a, e2 = c - a, h = glm::cross(d, e2);
    const float det = glm::dot(e1, h);
    if (std::abs(det) < 1e-12f) continue;
    const float f = 1.0f / det;
    const glm::vec3 sv = p - a;
    const float u = f * glm::dot(sv, h);
    if (u < 0 || u > 1) continue;
    const glm::vec3 q = glm::cross(sv, e1);
    const float v = f * glm::dot(d, q);
    if (v < 0 || u + v > 1) continue;
    if (f * glm::dot(e2, q) > 0) ++n;
  }
  return n % 2 == 1;
}

TEST(Geometry, ClosestPointOnTriangleRegions) {
  const glm::vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const glm::vec3 f = geom::closest_point_on_triangle({0.2f, 0.2f, 5}, a, b, c);  // face
  EXPECT_NEAR(glm::length(f - glm::vec3(0.2f, 0.2f, 0)), 0.0f, 1e-6f);
  EXPECT_EQ(geom::closest_point_on_triangle({-1, -1, 0}, a, b, c), a);                        // vertex
  EXPECT_EQ(geom::closest_point_on_triangle({0.5f, -2, 1}, a, b, c), glm::vec3(0.5f, 0, 0));  // edge
  const glm::vec3 q = geom::closest_point_on_triangle({1, 1, 0}, a, b, c);                    // hypotenuse
  EXPECT_NEAR(q.x, 0.5f, 1e-6f);
  EXPECT_NEAR(q.y, 0.5f, 1e-6f);
}

TEST(Geometry, TrianglesOverlapWhenTheyShareMoreThanAPoint) {
  using V = glm::vec3;
  const V a[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  auto t = [](V p, V q, V r) { return std::array<V, 3>{p, q, r}; };
  auto overlap = [&](const std::array<V, 3>& b) {
    const V bb[3] = {b[0], b[1], b[2]};
    return geom::triangles_overlap(a, bb);
  };
  EXPECT_TRUE(overlap(t({0.2f, 0.2f, -1}, {0.2f, 0.2f, 1}, {0.6f, 0.2f, 0})));  // pierces it
  EXPECT_FALSE(overlap(t({2, 0, -1}, {2, 0, 1}, {3, 0, 0})));                   // beside it
  EXPECT_FALSE(overlap(t({0, 0, 0}, {-1, 0, 1}, {0, -1, 1})));                  // one shared vertex: a touch
  EXPECT_FALSE(overlap(t({0, 0, 0}, {0, 0, 1}, {-1, -1, 1})));                  // two leaves on one petiole
  EXPECT_TRUE(overlap(t({0, 0, 0}, {1, 0, 0}, {0, 0, 1})));                     // hinged on a shared edge
  EXPECT_FALSE(overlap(t({0, 0, 0.01f}, {1, 0, 0.01f}, {0, 1, 0.01f})));        // parallel, a centimetre apart
  EXPECT_TRUE(overlap(t({0.1f, 0.1f, 0}, {2, 0.1f, 0}, {0.1f, 2, 0})));         // coplanar, sharing area
  EXPECT_TRUE(overlap(t({0, 0, 0}, {1, 0, 0}, {0, 1, 0})));                     // the same triangle
  EXPECT_FALSE(overlap(t({1, 0, 0}, {0, 1, 0}, {1, 1, 0})));                    // coplanar, sharing an edge only
  EXPECT_TRUE(overlap(t({0.1f, 0.1f, 1e-9f}, {0.5f, 0.1f, -1e-9f}, {0.1f, 0.5f, 0})));  // coplanar within rounding
}

TEST(Geometry, PrimitivesAreClosedAndOutward) {
  for (const auto& m :
       {geom::make_box("b", {0, 0, 0}, {1, 2, 3}), geom::make_cylinder("c", {0, 0, 0}, {0, 2, 0}, 0.5f, 0.3f, 16),
        geom::make_icosphere("s", {0, 0, 0}, 1.0f, 3)}) {
    EXPECT_TRUE(m.is_closed()) << m.name;
    Shape s;
    s.kind = Shape::Kind::Mesh;
    s.mesh = m;
    EXPECT_GT(s.volume(), 0.0) << m.name;
    // Outward: the signed volume (divergence theorem) is positive.
    double v = 0;
    for (const auto& t : m.triangles)
      v += glm::dot(glm::dvec3(m.vertices[t.x]), glm::cross(glm::dvec3(m.vertices[t.y]), glm::dvec3(m.vertices[t.z])));
    EXPECT_GT(v, 0.0) << m.name;
  }
  Shape box;
  box.kind = Shape::Kind::Mesh;
  box.mesh = geom::make_box("b", {0, 0, 0}, {1, 2, 3});
  EXPECT_NEAR(box.volume(), 6.0, 1e-5);
}

TEST(Geometry, FillSmallHolesClosesAScanButNotAWall) {
  // A finely tessellated sphere with two triangles removed: a small hole, filled.
  TriangleMesh holed = geom::make_icosphere("s", {0, 0, 0}, 1.0f, 4);
  holed.triangles.erase(holed.triangles.begin() + 10, holed.triangles.begin() + 12);
  ASSERT_FALSE(holed.is_closed());
  EXPECT_TRUE(geom::fill_small_holes(holed));
  EXPECT_TRUE(holed.is_closed());
  // A lone quad is all boundary: left open.
  TriangleMesh quad;
  quad.vertices = {{-1, 0, 0}, {1, 0, 0}, {1, 2, 0}, {-1, 2, 0}};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_FALSE(geom::fill_small_holes(quad));
  EXPECT_EQ(quad.triangles.size(), 2u);
}

// 2000 boxes centred in [-2, 2]^3 with half-sizes up to `half` (some thin), every seventh one empty
// when asked.
std::vector<Aabb> random_boxes(Rng& rng, float half, bool with_empty) {
  auto u = [&] { return static_cast<float>(rng.uniform()); };
  std::vector<Aabb> boxes(2000);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    if (with_empty && i % 7 == 0) continue;
    const glm::vec3 c(u() * 4 - 2, u() * 4 - 2, u() * 4 - 2),
        h(u() * half, u() * half, (u() * 0.02f + u() * 0.6f) * half);
    boxes[i].extend(c - h);
    boxes[i].extend(c + h);
  }
  return boxes;
}

// The box index visits every box that holds the point (and never an empty one); whatever extra boxes
// share a leaf are for the caller's own test to drop.
TEST(SceneQuery, BoxIndexVisitsEveryBoxHoldingThePoint) {
  const Scene scene = load_scene("boulder");
  const SceneQuery q(scene, {.build_sdf = false});
  Rng rng(3, 0, 0);
  auto u = [&] { return static_cast<float>(rng.uniform()); };
  const std::vector<Aabb> boxes = random_boxes(rng, 0.5f, true);
  const auto index = q.box_index(boxes);
  ASSERT_EQ(index->size(), boxes.size());
  std::size_t hits = 0;
  for (int k = 0; k < 500; ++k) {
    const glm::vec3 p(u() * 4 - 2, u() * 4 - 2, u() * 4 - 2);
    std::vector<std::uint32_t> seen;
    index->visit_containing(
        p,
        [](void* user, std::uint32_t id) {
          static_cast<std::vector<std::uint32_t>*>(user)->push_back(id);
          return false;
        },
        &seen);
    std::sort(seen.begin(), seen.end());
    for (std::uint32_t id = 0; id < boxes.size(); ++id) {
      const bool holds = !boxes[id].empty() && glm::all(glm::lessThanEqual(boxes[id].min, p)) &&
                         glm::all(glm::lessThanEqual(p, boxes[id].max));
      const bool visited = std::binary_search(seen.begin(), seen.end(), id);
      if (holds) {
        EXPECT_TRUE(visited) << "box " << id << " holds point " << k << " but was not visited";
        ++hits;
      }
      if (boxes[id].empty()) {
        EXPECT_FALSE(visited) << "empty box " << id << " visited";
      }
    }
  }
  EXPECT_GT(hits, 500u);  // the points do land in boxes
}

// Segment queries: every box the segment passes through well inside (not just grazing a face within
// rounding) is visited, and a visitor that answers true ends the query.
TEST(SceneQuery, BoxIndexVisitsEveryBoxTheSegmentPassesThrough) {
  const Scene scene = load_scene("boulder");
  const SceneQuery q(scene, {.build_sdf = false});
  Rng rng(5, 0, 0);
  auto u = [&] { return static_cast<float>(rng.uniform()); };
  const std::vector<Aabb> boxes = random_boxes(rng, 0.2f, false);
  const auto index = q.box_index(boxes);
  auto collect = [](void* user, std::uint32_t id) {
    static_cast<std::vector<std::uint32_t>*>(user)->push_back(id);
    return false;
  };
  std::size_t through = 0;
  for (int k = 0; k < 500; ++k) {
    const glm::vec3 o(u() * 4 - 2, u() * 4 - 2, u() * 4 - 2), d(u() - 0.5f, u() - 0.5f, u() - 0.5f);
    std::vector<std::uint32_t> seen;
    index->visit_segment(o, d, collect, &seen);
    std::sort(seen.begin(), seen.end());
    for (std::uint32_t id = 0; id < boxes.size(); ++id) {
      // The parameter interval of o + t d inside the box, in double (slab method), t in [0, 1].
      double t0 = 0.0, t1 = 1.0;
      for (int a = 0; a < 3; ++a) {
        const double lo = boxes[id].min[a], hi = boxes[id].max[a], oa = o[a], da = d[a];
        if (da == 0.0) {
          if (oa < lo || oa > hi) t1 = -1.0;
          continue;
        }
        const double ta = (lo - oa) / da, tb = (hi - oa) / da;
        t0 = std::max(t0, std::min(ta, tb));
        t1 = std::min(t1, std::max(ta, tb));
      }
      if (t1 - t0 > 1e-4) {
        EXPECT_TRUE(std::binary_search(seen.begin(), seen.end(), id))
            << "segment " << k << " passes through box " << id;
        ++through;
      }
    }
  }
  EXPECT_GT(through, 200u);
  // Stopping at the first box: one visit.
  int visits = 0;
  index->visit_segment(
      glm::vec3(-2.0f), glm::vec3(4.0f), [](void* user, std::uint32_t) { return ++*static_cast<int*>(user) > 0; },
      &visits);
  EXPECT_EQ(visits, 1);
}

TEST(SceneQuery, BoxDistancesMatchAnalyticWithinAVoxel) {
  const Scene s = scene_with(geom::make_box("box", {-1, -1, -1}, {1, 1, 1}));
  SceneQuery q(s, {.voxel_size = 0.02f});
  auto analytic = [](const glm::vec3& p) {
    const glm::vec3 d = glm::abs(p) - glm::vec3(1.0f);
    return glm::length(glm::max(d, glm::vec3(0.0f))) + std::min(std::max(d.x, std::max(d.y, d.z)), 0.0f);
  };
  Rng rng(3, 0);
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 p(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2));
    EXPECT_NEAR(q.signed_distance(p), analytic(p), q.voxel_size()) << p.x << "," << p.y << "," << p.z;
    EXPECT_NEAR(q.closest_point(p).distance, std::abs(analytic(p)), 1e-5f);
  }
  // Plane distances in front of a face, inside and beyond the narrow band.
  EXPECT_NEAR(q.signed_distance({0.1f, 0.2f, 1.03f}), 0.03f, 0.5f * q.voxel_size());
  EXPECT_NEAR(q.signed_distance({0.1f, 0.2f, 1.7f}), 0.7f, 1e-5f);
  EXPECT_NEAR(q.signed_distance({0.1f, 0.2f, 0.0f}), -0.8f, 1e-5f);  // deep inside: exact magnitude, band sign
  EXPECT_TRUE(q.inside({0.0f, 0.0f, 0.0f}));
  EXPECT_FALSE(q.inside({0.0f, 0.0f, 1.2f}));
  const glm::vec3 g = q.gradient({0.1f, 0.2f, 1.03f});
  EXPECT_NEAR(g.z, 1.0f, 1e-3f);
  EXPECT_NEAR(q.gradient({0.1f, 0.2f, 1.7f}).z, 1.0f, 1e-5f);
}

TEST(SceneQuery, SphereDistancesMatchAnalyticWithinAVoxel) {
  const float r = 0.8f;
  const Scene s = scene_with(geom::make_icosphere("sphere", {0.5f, 0.2f, -0.3f}, r, 5));
  SceneQuery q(s, {.voxel_size = 0.015f});
  const float sagitta = r * (1.0f - std::cos(0.5f * 0.0275f));  // icosphere level 5 flattening
  Rng rng(4, 0);
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 p = glm::vec3(0.5f, 0.2f, -0.3f) +
                        glm::vec3(rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5));
    const float analytic = glm::length(p - glm::vec3(0.5f, 0.2f, -0.3f)) - r;
    EXPECT_NEAR(q.signed_distance(p), analytic, q.voxel_size() + sagitta);
    if (std::abs(analytic) > q.voxel_size() + sagitta) {
      EXPECT_EQ(q.inside(p), analytic < 0.0f) << "at " << analytic;
    }
  }
}

// The band sample is the same trilinear value as signed_distance inside the band, its gradient is the
// sphere's radial direction, and outside the band it says so instead of guessing.
TEST(SceneQuery, BandSampleMatchesTheSphereAndKnowsItsBand) {
  const float r = 0.8f;
  const glm::vec3 c(0.5f, 0.2f, -0.3f);
  const Scene s = scene_with(geom::make_icosphere("sphere", c, r, 5));
  SceneQuery q(s, {.voxel_size = 0.015f});
  Rng rng(5, 0);
  int in_band = 0;
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 dir = rng.unit_vector();
    const float offset = static_cast<float>(rng.uniform(-0.1, 0.1));
    const glm::vec3 p = c + dir * (r + offset);
    const auto b = q.band_sample(p);
    if (std::abs(offset) < q.band_width() - 2.0f * q.voxel_size()) {
      ASSERT_TRUE(b.in_band) << offset;
      ++in_band;
      EXPECT_NEAR(b.distance, q.signed_distance(p), 1e-6f);  // same voxels, another summation order
      EXPECT_GT(glm::dot(b.gradient, dir), 0.99f) << offset;
      EXPECT_NEAR(glm::length(b.gradient), 1.0f, 1e-5f);
    } else if (std::abs(offset) > q.band_width()) {
      EXPECT_FALSE(b.in_band) << offset;
      EXPECT_EQ(b.distance, offset < 0.0f ? -q.band_width() : q.band_width());
      EXPECT_EQ(b.gradient, glm::vec3(0.0f));
    }
  }
  EXPECT_GT(in_band, 300);
}

TEST(SceneQuery, ClosestPointEqualsBruteForceOnStandardScenes) {
  for (const char* name : {"wall", "facade", "pergola", "boulder", "trunk"}) {
    const Scene s = load_scene(name);
    SceneQuery q(s, {.build_sdf = false});
    const Aabb b = s.bounds();
    Rng rng(5, 0);
    for (int i = 0; i < 300; ++i) {
      const glm::vec3 p = b.min + glm::vec3(rng.uniform(), rng.uniform(), rng.uniform()) * b.size();
      const ClosestHit h = q.closest_point(p);
      ASSERT_TRUE(h.found);
      EXPECT_NEAR(h.distance, brute_distance(s, p), 1e-5f) << name;
      EXPECT_NEAR(glm::length(h.point - p), h.distance, 1e-5f);
      // Bounded query: found exactly when within the radius.
      EXPECT_EQ(q.closest_point(p, 0.3f).found, h.distance < 0.3f) << name;
    }
  }
}

TEST(SceneQuery, ConcurrentQueriesAgreeWithSerial) {
  const Scene s = load_scene("boulder");
  SceneQuery q(s);
  std::vector<glm::vec3> pts(4000);
  Rng rng(6, 0);
  for (auto& p : pts) p = glm::vec3(rng.uniform(-2, 2), rng.uniform(0, 2), rng.uniform(-2, 2));
  std::vector<float> serial(pts.size()), parallel(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) serial[i] = q.signed_distance(pts[i]) + q.closest_point(pts[i]).distance;
  tbb::parallel_for(std::size_t{0}, pts.size(),
                    [&](std::size_t i) { parallel[i] = q.signed_distance(pts[i]) + q.closest_point(pts[i]).distance; });
  EXPECT_EQ(serial, parallel);
}

TEST(SceneQuery, OcclusionBehindAWall) {
  const Scene s = load_scene("wall");  // wall in z in [-0.1, 0.1], x in [-1.5, 1.5], y in [0, 2.5]
  SceneQuery q(s, {.build_sdf = false});
  EXPECT_TRUE(q.occluded({0, 1, 1}, {0, 0, -1}));
  EXPECT_FALSE(q.occluded({0, 1, 1}, {0, 0, 1}));
  EXPECT_FALSE(q.occluded({0, 1, 1}, {0, 0, -1}, 0.5f));  // stops short of the wall
  const RayHit h = q.ray({0, 1, 1}, {0, 0, -1});
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.t, 0.9f, 1e-5f);
  EXPECT_NEAR(h.normal.z, 1.0f, 1e-6f);
  // The default sun shines from the front (+z): the front face is lit, the back is in shadow.
  EXPECT_TRUE(q.light_visible({0, 1, 0.15f}));
  EXPECT_FALSE(q.light_visible({0, 1, -0.15f}));
}

// Embree aborts the process on a ray it cannot take (a component beyond about 1.8e18, or NaN): such a
// ray hits nothing, and such a point is in no light, whatever asked.
TEST(SceneQuery, RaysEmbreeCannotTakeHitNothingInsteadOfAborting) {
  const Scene s = load_scene("wall");
  SceneQuery q(s, {.build_sdf = false});
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (const glm::vec3 o : {glm::vec3(0, 2e18f, 1), glm::vec3(nan, 1, 1), glm::vec3(0, 1, inf)}) {
    EXPECT_FALSE(q.occluded(o, {0, 0, -1}));
    EXPECT_FALSE(q.ray(o, {0, 0, -1}).hit);
    EXPECT_FALSE(q.light_visible(o));
  }
  EXPECT_FALSE(q.ray({0, 1, 1}, {0, 0, -3e18f}).hit);
  EXPECT_FALSE(q.ray({0, 1, 1}, {0, 0, -1}, nan).hit);
  const auto occ = q.occluder({{{0, 1, 0.5f}, {1, 1, 0.5f}, 0.1f, 0.1f}}, {});
  EXPECT_TRUE(occ->occluded({0.5f, 1, 1}, {0, 0, -1}, 2.0f));
  EXPECT_FALSE(occ->occluded({0.5f, 2e18f, 1}, {0, 0, -1}, 2.0f));
  // A far origin within Embree's range is still traced.
  EXPECT_TRUE(q.occluded({0, 1, 1e6f}, {0, 0, -1}));
}

// The scan is sealed when it is loaded: Embree, the distance field and the inside test see one solid.
TEST(SceneQuery, InsideOutsideOfTheSealedBunnyMatchesRayParity) {
  EXPECT_FALSE(load_obj(mesh_path("stanford-bunny")).is_closed())
      << "the scan has five small holes (223 boundary edges)";
  const Scene s = load_scene("mesh:stanford-bunny");
  ASSERT_TRUE(s.meshes[0].is_closed()) << "sealed by load_scene_obj";
  SceneQuery q(s);
  ASSERT_TRUE(q.mesh_solid()[0]);
  const Aabb b = s.meshes[0].bounds();
  Rng rng(7, 0);
  int inside = 0, near = 0;
  for (int i = 0; i < 1200; ++i) {
    glm::vec3 p;
    if (i % 2 == 0) {
      p = b.min + glm::vec3(rng.uniform(), rng.uniform(), rng.uniform()) * b.size();
    } else {  // within a few millimetres of the surface, either side: where the field cannot tell
      const SurfaceSample ss = q.sample_surface(11, static_cast<std::uint64_t>(i));
      p = ss.position + static_cast<float>(rng.uniform() * 0.008 - 0.004) * ss.normal;
      if (brute_distance(s, p) < 2e-4f) continue;  // too close for a float ray to call
      ++near;
    }
    const bool ref = brute_inside(s.meshes[0], p);
    EXPECT_EQ(q.inside(p), ref) << "at " << p.x << "," << p.y << "," << p.z << " field " << q.signed_distance(p);
    inside += ref ? 1 : 0;
  }
  EXPECT_GT(near, 450);
  EXPECT_GT(inside, 200);  // the test really visits the inside
}

// In a concave crease the trilinear field reads negative a little outside (the corner's roof over its
// walls, the facade's ledge over its piers); inside() does not. The scenes are boxes, so the exact
// answer is whether a point is strictly within one of their boxes.
TEST(SceneQuery, InsideIsExactInCreasesWhereTheFieldIsNot) {
  int misread = 0;
  for (const char* name : {"corner", "facade", "pergola", "wall"}) {
    const Scene s = load_scene(name);
    SceneQuery q(s);
    Rng rng(3, 0);
    int checked = 0;
    for (int i = 0; i < 4000; ++i) {
      const SurfaceSample ss = q.sample_surface(5, static_cast<std::uint64_t>(i));
      const glm::vec3 dir =
          glm::normalize(glm::vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) + glm::vec3(1e-3f));
      const glm::vec3 p = ss.position + static_cast<float>(rng.uniform() * 0.03) * dir;
      bool in = false, on_face = false;
      for (const auto& m : s.meshes) {
        ASSERT_EQ(m.vertices.size(), 8u) << name << ": a box";
        const Aabb box = m.bounds();
        const glm::vec3 lo = p - box.min, hi = box.max - p;
        const float depth = std::min({lo.x, lo.y, lo.z, hi.x, hi.y, hi.z});
        in = in || depth > 0.0f;
        on_face = on_face || std::abs(depth) < 1e-5f;
      }
      if (on_face) continue;
      ++checked;
      EXPECT_EQ(q.inside(p), in) << name << " at " << p.x << "," << p.y << "," << p.z;
      misread += (q.signed_distance(p) < 0.0f) != in ? 1 : 0;
    }
    EXPECT_GT(checked, 3500) << name;
  }
  EXPECT_GT(misread, 0) << "the field's sign alone is wrong somewhere here, or this test proves nothing";
}

// Points on the far side of an edge or a vertex of a closed mesh, where a face normal alone gives the
// wrong side: the pseudonormal of the feature decides.
TEST(SceneQuery, InsideAtEdgesAndVerticesOfACube) {
  const Scene s = scene_with(geom::make_box("cube", {-1, -1, -1}, {1, 1, 1}));
  for (const bool field : {true, false}) {
    SceneQuery q(s, {.build_sdf = field});
    for (const float e : {1e-4f, 1e-2f, 0.3f}) {
      EXPECT_FALSE(q.inside({1 + e, 1 + e, 0})) << e;      // beyond an edge
      EXPECT_FALSE(q.inside({1 + e, 1 + e, 1 + e})) << e;  // beyond a vertex
      EXPECT_FALSE(q.inside({1 + e, 1 - e * 0.5f, 0.2f})) << e;
      EXPECT_TRUE(q.inside({1 - e, 1 - e, 0})) << e;      // within an edge
      EXPECT_TRUE(q.inside({1 - e, 1 - e, 1 - e})) << e;  // within a vertex
      EXPECT_TRUE(q.inside_mesh(0, {1 - e, 1 - e * 2, 1 - e})) << e;
    }
    EXPECT_FALSE(q.inside({1, 0.5f, 0.5f}));  // on the surface: outside
    EXPECT_FALSE(q.inside({3, 3, 3}));
    EXPECT_TRUE(q.inside({0, 0, 0}));
  }
}

TEST(SceneQuery, OpenMeshHasNoInside) {
  TriangleMesh quad;
  quad.name = "quad";
  quad.vertices = {{-1, 0, 0}, {1, 0, 0}, {1, 2, 0}, {-1, 2, 0}};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  const Scene s = scene_with(quad);
  SceneQuery q(s, {.voxel_size = 0.02f});
  EXPECT_FALSE(q.mesh_solid()[0]);
  for (const float z : {-0.5f, -0.03f, -0.001f, 0.001f, 0.03f, 0.5f}) {
    EXPECT_FALSE(q.inside({0, 1, z})) << z;
    EXPECT_NEAR(q.signed_distance({0, 1, z}), std::abs(z), q.voxel_size()) << z;
  }
}

TEST(SceneQuery, SurfaceSamplesAreAreaWeightedAndOnClimbableMeshes) {
  const Scene s = load_scene("wall");
  SceneQuery q(s, {.build_sdf = false});
  // The ground is not climbable: every sample lies on the wall box. Area of the faces:
  // front/back 3 x 2.55 each, sides 0.2 x 2.55 each, top and bottom 3 x 0.2 each.
  const double front = 3.0 * 2.55, side = 0.2 * 2.55, top = 3.0 * 0.2;
  const double total = 2 * front + 2 * side + 2 * top;
  EXPECT_NEAR(q.sampled_area(), total, 1e-3);
  int front_hits = 0;
  const int n = 40000;
  for (int i = 0; i < n; ++i) {
    const SurfaceSample sm = q.sample_surface(9, static_cast<std::uint64_t>(i));
    ASSERT_EQ(s.meshes[sm.mesh].name, "wall");
    if (std::abs(sm.position.z - 0.1f) < 1e-5f) ++front_hits;
    EXPECT_NEAR(q.closest_point(sm.position).distance, 0.0f, 1e-4f);
  }
  const double expected = front / total;
  EXPECT_NEAR(front_hits / double(n), expected, 5 * std::sqrt(expected * (1 - expected) / n));
}

// OpenVDB threw "ArithmeticError: Non-zero scale values required", which named no parameter.
TEST(SceneQuery, AVoxelSizeOpenVdbCannotRepresentIsAnInputError) {
  const Scene s = load_scene("wall");
  SceneQueryOptions o;
  o.voxel_size = 1e-5f;
  EXPECT_EQ(test::error_of([&] { SceneQuery q(s, o); }),
            "scene 'wall': --voxel-size 1e-05 is below 1.46e-05 m, the smallest voxel OpenVDB represents");
  Scene tiny = test::scene_with(geom::make_box("speck", glm::vec3(0.0f), glm::vec3(1e-3f)));
  const std::string e = test::error_of([&] { SceneQuery q(tiny); });
  EXPECT_EQ(e.rfind("scene 'test': the automatic voxel size 6.7", 0), 0u) << e;
  EXPECT_NE(e.find("is below 1.46e-05 m, the smallest voxel OpenVDB represents; the scene is too small: scale it up, "
                   "or give --voxel-size"),
            std::string::npos)
      << e;
}

// A voxel size that needs more memory than there is ran into OpenVDB and ended in SIGABRT under a limit.
// The field at 0.1 mm on the wall needs terabytes: refused before anything is allocated.
TEST(SceneQuery, ADistanceFieldTooLargeForMemoryIsRefusedBeforeItIsBuilt) {
  const Scene s = load_scene("wall");
  SceneQueryOptions o;
  o.voxel_size = 1e-4f;
  try {
    SceneQuery q(s, o);
    ADD_FAILURE() << "built a field at 0.1 mm";
  } catch (const OutOfMemoryError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("scene 'wall': the distance field at --voxel-size 0.0001 would need about ", 0), 0u) << m;
    EXPECT_NE(m.find("TiB, more than the "), std::string::npos) << m;
    EXPECT_NE(m.find(" this process may still take; a larger --voxel-size needs less (a quarter for twice the size)"),
              std::string::npos)
        << m;
  }
}

}  // namespace
}  // namespace growbench
