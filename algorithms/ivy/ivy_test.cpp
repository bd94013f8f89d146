// The Luft-style ivy: Luft's per-triangle rules on cases with known answers, the branching sampler
// against Luft's node-by-node loop, the Embree path against a brute-force reference over all triangles,
// and what every ivy must do on real scenes (no node inside a solid, attached to the wall, leaves
// facing away from it, Blender's limits).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>

#include <nlohmann/json.hpp>

#include "algorithms/ivy/ivy.hpp"
#include "scenes/geometry.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"
#include "test_util.hpp"
#include "grow_util.hpp"

namespace growbench {
namespace {

using ivy::Triangle;

Triangle make_tri(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  Scene s;
  TriangleMesh m;
  m.vertices = {a, b, c};
  m.triangles = {{0, 1, 2}};
  s.meshes.push_back(m);
  return ivy::TriangleTable(s).tris[0];
}

// The unit right triangle in z = 0, normal +z.
const Triangle kFloor = make_tri({0, 0, 0}, {1, 0, 0}, {0, 1, 0});

TEST(IvyRules, AdhesionCountsFaceInteriorsFromTheFrontOnly) {
  glm::vec3 foot;
  EXPECT_FLOAT_EQ(ivy::adhesion_distance(kFloor, {0.2f, 0.2f, 0.5f}, foot), 0.5f);
  EXPECT_EQ(foot, glm::vec3(0.2f, 0.2f, 0.0f));
  EXPECT_LT(ivy::adhesion_distance(kFloor, {0.2f, 0.2f, -0.5f}, foot), 0.0f) << "back side";
  EXPECT_LT(ivy::adhesion_distance(kFloor, {0.8f, 0.8f, 0.1f}, foot), 0.0f) << "projects outside the face";
  // The true closest point would be the vertex at 0.1 away; Luft's rule ignores it.
  EXPECT_LT(ivy::adhesion_distance(kFloor, {-0.1f, 0.0f, 0.0f}, foot), 0.0f);
}

TEST(IvyRules, AdhesionSearchPicksTheNearestAndBreaksTiesByIndex) {
  ivy::AdhesionSearch s{{0.2f, 0.2f, 0.3f}, 1.0f, true};
  const Triangle higher = make_tri({0, 0, 0.1f}, {1, 0, 0.1f}, {0, 1, 0.1f});  // 0.2 away
  EXPECT_TRUE(s.offer(kFloor, 7, geom::closest_point_on_triangle));
  EXPECT_TRUE(s.offer(higher, 9, geom::closest_point_on_triangle));
  EXPECT_FALSE(s.offer(higher, 12, geom::closest_point_on_triangle)) << "a tie keeps the lower index";
  EXPECT_TRUE(s.offer(higher, 3, geom::closest_point_on_triangle)) << "a tie goes to the lower index";
  EXPECT_EQ(s.best_id, 3u);
  EXPECT_NEAR(s.best, 0.2f, 1e-6f);
  // normalize(foot - p) * (1 - d / max): straight down, 0.8 long.
  const glm::vec3 v = s.vector();
  EXPECT_NEAR(v.z, -0.8f, 1e-6f);
  EXPECT_NEAR(glm::length(glm::vec2(v.x, v.y)), 0.0f, 1e-6f);
  ivy::AdhesionSearch far{{0.2f, 0.2f, 0.3f}, 0.25f, true};
  EXPECT_FALSE(far.offer(kFloor, 0, geom::closest_point_on_triangle)) << "beyond max_adhesion_distance";
  EXPECT_EQ(far.vector(), glm::vec3(0.0f));
  ivy::AdhesionSearch closest{{-0.3f, 0.2f, 0.4f}, 1.0f, false};
  EXPECT_TRUE(closest.offer(kFloor, 0, geom::closest_point_on_triangle)) << "closest mode counts edges";
  EXPECT_NEAR(closest.best, 0.5f, 1e-6f);
}

TEST(IvyRules, CollisionMirrorsEnteringSegmentsOnly) {
  EXPECT_TRUE(ivy::crosses(kFloor, {0.2f, 0.2f, 0.5f}, {0.2f, 0.2f, -0.3f}));
  EXPECT_FALSE(ivy::crosses(kFloor, {0.2f, 0.2f, -0.5f}, {0.2f, 0.2f, 0.3f})) << "leaving";
  EXPECT_FALSE(ivy::crosses(kFloor, {0.2f, 0.2f, 0.5f}, {0.2f, 0.2f, 0.1f})) << "stops short";
  EXPECT_FALSE(ivy::crosses(kFloor, {0.9f, 0.9f, 0.5f}, {0.9f, 0.9f, -0.3f})) << "misses the face";
  Scene s;
  TriangleMesh m;
  m.vertices = {{-5, -5, 0}, {5, -5, 0}, {0, 5, 0}};
  m.triangles = {{0, 1, 2}};
  s.meshes.push_back(m);
  const ivy::TriangleTable table(s);
  const std::uint32_t ids[] = {0};
  glm::vec3 q(0.2f, 0.2f, -0.3f);
  const auto r = ivy::collide(table, ids, {0.1f, 0.1f, 0.5f}, q);
  EXPECT_TRUE(r.climbing);
  EXPECT_TRUE(r.alive);
  EXPECT_EQ(r.reflections, 1);
  EXPECT_NEAR(q.z, 0.3f, 1e-6f);
  EXPECT_FLOAT_EQ(q.x, 0.2f);
}

TEST(IvyRules, ARootStillBouncingInTheSixthPassDies) {
  // Two big faces 0.1 apart, facing each other; the candidate keeps bouncing between them.
  Scene s;
  TriangleMesh m;
  m.vertices = {{-5, -5, 0}, {5, -5, 0}, {0, 5, 0}, {-5, -5, 0.1f}, {0, 5, 0.1f}, {5, -5, 0.1f}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  s.meshes.push_back(m);
  const ivy::TriangleTable table(s);
  ASSERT_GT(table.tris[0].n.z, 0.9f);
  ASSERT_LT(table.tris[1].n.z, -0.9f);
  const std::uint32_t ids[] = {0, 1};
  // Each pass mirrors across both faces and brings the candidate 0.2 closer: -0.813, -0.613, ...,
  // -0.013 after five passes, +0.013 (between the faces) after the first mirror of the sixth. The
  // seventh pass mirrors nothing, but Luft's counter kills the root after it all the same.
  glm::vec3 q(0.0f, 0.0f, -1.013f);
  const auto r = ivy::collide(table, ids, {0.0f, 0.0f, 0.05f}, q);
  EXPECT_EQ(r.reflections, 11);
  EXPECT_NEAR(q.z, 0.013f, 1e-5f);
  EXPECT_FALSE(r.alive);
  glm::vec3 q2(0.0f, 0.0f, -0.613f);  // resolved in the fourth pass: lives
  EXPECT_TRUE(ivy::collide(table, ids, {0.0f, 0.0f, 0.05f}, q2).alive);
}

TEST(IvyBranching, ThinnedSamplerMatchesLuftsNodeLoop) {
  // A root of 400 unequal segments; Luft's loop draws once per node and takes the first success.
  std::vector<float> len(400);
  for (std::size_t k = 1; k < len.size(); ++k) len[k] = len[k - 1] + 0.5f + static_cast<float>(k % 7) * 0.1f;
  auto length = [&](std::size_t k) { return len[k]; };
  for (const float b : {0.95f, 0.6f, 0.05f}) {
    constexpr int kTrials = 40000;
    std::vector<double> fast(len.size() + 1, 0.0), naive(len.size() + 1, 0.0);
    for (int t = 0; t < kTrials; ++t) {
      Rng r1(11, 1, static_cast<std::uint64_t>(t) << 20), r2(12, 2, static_cast<std::uint64_t>(t) << 20);
      const auto k = ivy::sample_branch_node(len.size(), length, b, r1);
      fast[k < 0 ? len.size() : static_cast<std::size_t>(k)] += 1.0;
      std::size_t hit = len.size();
      for (std::size_t j = 0; j < len.size(); ++j)
        if (r2.uniform() * ivy::branch_weight(len[j] / len.back()) > b) {
          hit = j;
          break;
        }
      naive[hit] += 1.0;
    }
    // Compare the two distributions in 20 bins of node index plus "no branch": every bin within 5
    // standard errors (a wrong window or acceptance shifts whole bins by far more).
    std::vector<double> bf(21, 0.0), bn(21, 0.0);
    for (std::size_t k = 0; k <= len.size(); ++k) {
      const std::size_t bin = k == len.size() ? 20 : k * 20 / len.size();
      bf[bin] += fast[k];
      bn[bin] += naive[k];
    }
    for (std::size_t i = 0; i < 21; ++i) {
      const double pf = bf[i] / kTrials, pn = bn[i] / kTrials;
      const double se = std::sqrt((pf * (1 - pf) + pn * (1 - pn)) / kTrials) + 1e-9;
      EXPECT_LT(std::abs(pf - pn), 5.0 * se + 1e-3) << "b=" << b << " bin " << i << ": " << pf << " vs " << pn;
    }
  }
}

// Luft's own algorithm: every triangle for the adhesion, every triangle as a collision candidate.
class BruteForceGeometry final : public ivy::Geometry {
 public:
  BruteForceGeometry(const ivy::TriangleTable& t, const ivy::Config& c, const SceneQuery& q, bool reverse = false)
      : t_(t), c_(c), q_(q), reverse_(reverse) {}
  glm::vec3 adhesion(const glm::vec3& p, std::uint32_t& hint) const override {
    ivy::AdhesionSearch s{p, c_.max_adhesion, c_.adhesion_mode == ivy::AdhesionMode::Luft};
    const auto n = static_cast<std::uint32_t>(t_.size());
    for (std::uint32_t i = 0; i < n; ++i) {
      const std::uint32_t id = reverse_ ? n - 1 - i : i;  // the order must not matter
      s.offer(t_.tris[id], id, geom::closest_point_on_triangle);
    }
    hint = s.best_id;
    return s.vector();
  }
  void gather(const glm::vec3&, float, ivy::Candidates& candidates) const override {
    for (std::uint32_t id = 0; id < t_.size(); ++id) candidates.push(id);  // every triangle, as Luft
  }
  bool crosses_any(const glm::vec3& o, const glm::vec3& q, ivy::Lookahead&) const override {
    for (const auto& t : t_.tris)
      if (ivy::crosses(t, o, q)) return true;
    return false;
  }
  RayHit first_hit(const glm::vec3& o, const glm::vec3& d) const override { return q_.ray(o, d, 1.0f, 0.0f); }

 private:
  const ivy::TriangleTable& t_;
  ivy::Config c_;
  const SceneQuery& q_;
  bool reverse_;
};

Plant grow_with(const Scene& scene, const SceneQuery& query, bool brute, std::uint64_t seed, int steps,
                const std::vector<std::string>& sets = {}) {
  Params p = default_params(find_algorithm("ivy"));
  for (const auto& s : sets) p.set_assignment(s);
  const ivy::TriangleTable table(scene);
  const ivy::Config cfg = ivy::make_config(p, scene);
  std::unique_ptr<ivy::Geometry> g;
  if (brute)
    g = std::make_unique<BruteForceGeometry>(table, cfg, query);
  else
    g = ivy::make_embree_geometry(query, table, cfg);
  ivy::Grower grower(scene, *g, table, cfg, seed);
  for (int i = 0; i < steps && grower.step(); ++i) {
  }
  grower.finish();
  return grower.plant();
}

TEST(IvyReference, EmbreePathGrowsExactlyLuftsBruteForcePlant) {
  // Small meshes (tens to a few thousand triangles) where looping over all of them stays cheap.
  const std::vector<std::pair<std::string, std::vector<std::string>>> scenes = {
      {"wall", {}}, {"column", {}}, {"boulder", {}}, {"corner", {}}};
  for (const auto& [name, scene_params] : scenes) {
    const Scene scene = load_scene(name, scene_params);
    const SceneQuery query(scene, {.build_sdf = false});
    for (const std::uint64_t seed : {1u, 2u, 3u}) {
      const Plant fast = grow_with(scene, query, false, seed, 120);
      const Plant slow = grow_with(scene, query, true, seed, 120);
      ASSERT_GT(fast.nodes.size(), 200u) << name;
      EXPECT_EQ(fast.nodes.size(), slow.nodes.size()) << name << " seed " << seed;
      EXPECT_EQ(fast.geometry_hash(), slow.geometry_hash()) << name << " seed " << seed;
    }
  }
}

// Query by query on a scanned mesh of 70k triangles (too many to grow a brute-force plant on): the
// Embree path's adhesion vector, target and collision candidates equal the brute-force ones, in both
// adhesion modes, whichever triangle a clinging root offers first and in whichever order the brute
// force loops. Points: random ones on, above, below and far from the surface, and near-ties on the
// bisector of two faces sharing an edge, where the two distances differ only by rounding (the case
// in which a rejection test without enough slack let the triangle offered first win).
// It is long because its checks share the bunny's tables and the per-mode tallies the last expectations
// read; split, each piece would take them all as arguments.
TEST(IvyReference, EmbreeAdhesionEqualsBruteForceOnTheBunny) {
  // The scan as it is, unsealed, so that the rims of its holes are exercised too (any open OBJ has them).
  Scene bunny = load_scene("mesh:stanford-bunny"), raw;
  raw.meshes.push_back(load_obj(mesh_path("stanford-bunny")));
  fit_scene(raw, 2.0f);  // as the mesh scene places it
  bunny.meshes[0] = raw.meshes[0];
  const SceneQuery query(bunny, {.build_sdf = false});
  const ivy::TriangleTable table(bunny);
  // The triangle across t's edge a-b (kNoTriangle on the rim of a hole), and the edge's midpoint.
  auto neighbour = [&](std::uint32_t t, glm::vec3& mid) -> std::uint32_t {
    const ivy::Triangle& x = table.tris[t];
    mid = 0.5f * (x.a + x.b);
    for (std::uint32_t id = 0; id < table.size(); ++id) {
      const ivy::Triangle& y = table.tris[id];
      auto has = [&](const glm::vec3& v) { return y.a == v || y.b == v || y.c == v; };
      if (id != t && has(x.a) && has(x.b)) return id;
    }
    return ivy::kNoTriangle;
  };
  // How many triangles share each edge (endpoints ordered), to find the rims of holes.
  auto edge_key = [](const glm::vec3& p, const glm::vec3& q) {
    const std::array<float, 3> a{p.x, p.y, p.z}, b{q.x, q.y, q.z};
    return a < b ? std::pair(a, b) : std::pair(b, a);
  };
  std::map<std::pair<std::array<float, 3>, std::array<float, 3>>, int> edges;
  for (const auto& x : table.tris) {
    ++edges[edge_key(x.a, x.b)];
    ++edges[edge_key(x.b, x.c)];
    ++edges[edge_key(x.c, x.a)];
  }
  for (const char* mode : {"luft", "closest"}) {
    Params params = default_params(find_algorithm("ivy"));
    params.set_assignment(std::string("adhesion=") + mode);
    const ivy::Config cfg = ivy::make_config(params, bunny);
    const auto fast = ivy::make_embree_geometry(query, table, cfg);
    const BruteForceGeometry slow(table, cfg, query), reversed(table, cfg, query, true);
    Rng rng(7, 0, 0);
    int attracted = 0, none = 0, ties = 0;
    auto check = [&](const glm::vec3& p, float gather, std::initializer_list<std::uint32_t> hints, int i) {
      std::uint32_t hf = ivy::kNoTriangle, hs = ivy::kNoTriangle, hr = ivy::kNoTriangle;
      const glm::vec3 af = fast->adhesion(p, hf);
      const glm::vec3 as = slow.adhesion(p, hs);
      const glm::vec3 ar = reversed.adhesion(p, hr);
      ASSERT_EQ(hf, hs) << mode << " point " << i;
      ASSERT_EQ(af, as) << mode << " point " << i;
      ASSERT_EQ(hr, hs) << mode << " point " << i << ": offering the triangles in reverse order changed the target";
      ASSERT_EQ(ar, as) << mode << " point " << i;
      // A clinging root offers its previous target first: no hint changes the answer.
      for (std::uint32_t h : hints) {
        std::uint32_t hint = h;
        ASSERT_EQ(fast->adhesion(p, hint), as) << mode << " point " << i << " hint " << h;
        ASSERT_EQ(hint, hs) << mode << " point " << i << " hint " << h;
      }
      // The collision candidates: every triangle within gather, and only triangles whose bounds are.
      ivy::Candidates cf;
      fast->gather(p, gather, cf);
      const auto fs = cf.sorted_unique();
      const std::vector<std::uint32_t> got(fs.begin(), fs.end());
      for (std::uint32_t id = 0; id < table.size(); ++id) {
        const auto& t = table.tris[id];
        const bool near = glm::length(p - geom::closest_point_on_triangle(p, t.a, t.b, t.c)) < gather * (1.0f - 1e-5f);
        const bool listed = std::binary_search(got.begin(), got.end(), id);
        if (near) {
          ASSERT_TRUE(listed) << mode << " point " << i << " triangle " << id;
        }
        if (listed) {
          ASSERT_LE(ivy::box_distance2(t, p), gather * gather) << mode << " point " << i << " triangle " << id;
        }
      }
      (hf == ivy::kNoTriangle ? none : attracted) += 1;
    };
    // Luft's collision question, whether the segment crosses any triangle, as the box index answers it
    // and as the loop over every triangle does.
    int crossed = 0, clear = 0, settled = 0;
    auto cross = [&](const glm::vec3& o, const glm::vec3& q, int i) {
      ivy::Lookahead none_ahead, ahead;
      const bool want = slow.crosses_any(o, q, none_ahead);
      ASSERT_EQ(fast->crosses_any(o, q, ahead), want) << mode << " segment " << i;
      (want ? crossed : clear) += 1;
      // A clear segment may settle the adhesion at its end on the way: then it is adhesion(q)'s.
      ASSERT_FALSE(want && ahead.valid) << mode << " segment " << i;
      if (ahead.valid) {
        std::uint32_t hint = ivy::kNoTriangle;
        ASSERT_EQ(ahead.vector, slow.adhesion(q, hint)) << mode << " segment " << i;
        ASSERT_EQ(ahead.hint, hint) << mode << " segment " << i;
        ++settled;
      }
    };
    for (int i = 0; i < 300; ++i) {
      const SurfaceSample s = query.sample_surface(11, static_cast<std::uint64_t>(i));
      // From just inside to beyond the adhesion distance, with a sideways jitter of a few steps.
      const float off = static_cast<float>(rng.uniform() * 1.4 - 0.1) * cfg.max_adhesion;
      const glm::vec3 jitter(static_cast<float>(rng.uniform() - 0.5), static_cast<float>(rng.uniform() - 0.5),
                             static_cast<float>(rng.uniform() - 0.5));
      const glm::vec3 p = s.position + off * s.normal + 4.0f * cfg.step * jitter;
      const float gather = cfg.step * static_cast<float>(0.2 + 2.0 * rng.uniform());
      check(p, gather, {s.triangle}, i);
      if (HasFatalFailure()) return;
      // Through the surface just below the sample, and one step in the jitter's direction.
      cross(p, s.position - 0.3f * cfg.step * s.normal + cfg.step * jitter, i);
      cross(p, p + cfg.step * jitter, 500 + i);
      if (HasFatalFailure()) return;
    }
    for (int i = 0; i < 300; ++i) {
      const SurfaceSample s = query.sample_surface(12, static_cast<std::uint64_t>(i));
      glm::vec3 mid;
      const std::uint32_t u = neighbour(s.triangle, mid);
      if (u == ivy::kNoTriangle) continue;  // on the rim of a hole: see below
      const glm::vec3 bisector = table.tris[s.triangle].n + table.tris[u].n;
      if (glm::length(bisector) < 0.1f) continue;
      const float h = static_cast<float>(0.002 + 0.05 * rng.uniform()) * cfg.max_adhesion;
      check(mid + h * glm::normalize(bisector), cfg.step, {s.triangle, u}, 1000 + i);
      cross(mid + h * glm::normalize(bisector), mid - 0.5f * h * glm::normalize(bisector), 1000 + i);  // on the edge
      // Through a vertex, where the crossing lies on a corner of the triangles' boxes to within rounding.
      const glm::vec3 v = table.tris[s.triangle].a;
      cross(v + h * glm::normalize(bisector), v - 0.5f * h * glm::normalize(bisector), 3000 + i);
      if (HasFatalFailure()) return;
      ++ties;
    }
    // The rims of the scan's holes, where a crossing on the edge has no neighbour to fall into: through
    // the middle of every rim edge and through its ends.
    int rim = 0;
    for (std::uint32_t t = 0; t < table.size(); ++t) {
      const ivy::Triangle& x = table.tris[t];
      const glm::vec3 v[3] = {x.a, x.b, x.c};
      for (int e = 0; e < 3; ++e) {
        const auto key = edge_key(v[e], v[(e + 1) % 3]);
        if (edges.at(key) != 1) continue;
        for (const glm::vec3& at : {0.5f * (v[e] + v[(e + 1) % 3]), v[e]}) {
          cross(at + cfg.step * x.n, at - cfg.step * x.n, 5000 + rim);
          if (HasFatalFailure()) return;
        }
        ++rim;
      }
    }
    EXPECT_GT(rim, 200) << mode;
    // Both outcomes and the near-ties were exercised.
    EXPECT_GT(attracted, 100) << mode;
    EXPECT_GT(ties, 200) << mode;
    EXPECT_GT(crossed, 300) << mode;
    EXPECT_GT(clear, 150) << mode;
    if (std::string(mode) == "luft") {
      EXPECT_GT(none, 20) << mode;
      EXPECT_EQ(settled, clear) << "every clear segment settles the adhesion at its end in luft mode";
    } else {
      EXPECT_EQ(settled, 0) << "closest adhesion is never settled by the crossing test";
    }
  }
}

TEST(IvyReference, ClosestAdhesionModeAgreesWithBruteForceToo) {
  const Scene scene = load_scene("boulder");
  const SceneQuery query(scene, {.build_sdf = false});
  const Plant fast = grow_with(scene, query, false, 4, 120, {"adhesion=closest"});
  const Plant slow = grow_with(scene, query, true, 4, 120, {"adhesion=closest"});
  EXPECT_EQ(fast.geometry_hash(), slow.geometry_hash());
}

std::size_t nodes_inside(const Plant& p, const SceneQuery& q) {
  return test::nodes_inside_solids(p, q).size();
}

TEST(IvyScenes, NoNodeEndsInsideAClosedMesh) {
  for (const std::string name : {"column", "boulder"}) {
    const Scene scene = load_scene(name);
    const SceneQuery q(scene);
    const Plant p = test::grow("ivy", scene, q, {"max_root_length=1.5"}, 0, 5);
    ASSERT_GT(p.nodes.size(), 1000u) << name;
    EXPECT_EQ(nodes_inside(p, q), 0u) << name;
  }
  Scene bunny = load_scene("mesh:stanford-bunny");
  const SceneQuery q(bunny);
  // The scan's lowest vertex (the default seed) is on the rim of a hole in its base; start on its flank.
  bunny.seeds = {{q.closest_point({0.0f, 0.8f, 1.0f}).point, {0, 1, 0}, 0}};
  const Plant luft = test::grow("ivy", bunny, q, {"max_root_length=1.5"}, 0, 7);
  ASSERT_GT(luft.nodes.size(), 1000u);
  EXPECT_EQ(nodes_inside(luft, q), 0u);
  // Blender's collision mirrors once across the first face hit and never re-checks, so at a crease
  // the mirrored candidate can land behind a second face: a few nodes do end inside, as in Blender.
  const Plant blender = test::grow("ivy", bunny, q, {"preset=blender"}, 0, 7);
  ASSERT_GT(blender.nodes.size(), 300u);
  EXPECT_LT(static_cast<double>(nodes_inside(blender, q)), 0.01 * static_cast<double>(blender.nodes.size()));
}

TEST(IvyScenes, IvyClingsToTheWallAndItsLeavesFaceAway) {
  const Scene scene = load_scene("wall");
  const SceneQuery q(scene);
  const Plant p = test::grow("ivy", scene, q, {}, 0, 1, 300);
  ASSERT_GT(p.nodes.size(), 20000u);
  std::size_t attached = 0;
  for (const auto& n : p.nodes) attached += q.closest_point(n.position).distance < 0.02f ? 1 : 0;
  EXPECT_GT(static_cast<double>(attached) / static_cast<double>(p.nodes.size()), 0.6) << "within 2 cm of a surface";
  // Leaves on the wall's faces (not above its top or on the ground): their normal points away from
  // the face they sit on.
  std::size_t on_face = 0, away = 0;
  for (const auto& o : p.organs) {
    const glm::vec3 centre = o.position + 0.5f * o.size * (glm::mat3_cast(o.orientation) * glm::vec3(0, 0, 1));
    const ClosestHit h = q.closest_point(centre);
    if (std::abs(h.normal.z) < 0.9f || h.distance > 0.05f || centre.y < 0.2f || centre.y > 2.3f) continue;
    ++on_face;
    const glm::vec3 n = glm::mat3_cast(o.orientation) * glm::vec3(0, 1, 0);
    away += glm::dot(n, h.normal) > 0.0f ? 1 : 0;
  }
  ASSERT_GT(on_face, 1000u);
  EXPECT_GT(static_cast<double>(away) / static_cast<double>(on_face), 0.95);
}

TEST(IvyScenes, BlenderPresetStopsAtItsMaximumRootLength) {
  Scene bunny = load_scene("mesh:stanford-bunny");
  const SceneQuery q(bunny, {.build_sdf = false});
  bunny.seeds = {{q.closest_point({0.0f, 0.8f, 1.0f}).point, {0, 1, 0}, 0}};
  std::vector<std::pair<std::string, double>> stats;
  const Plant p = test::grow("ivy", bunny, q, {"preset=blender"}, 0, 1, 5000, &stats);
  auto stat = [&](const std::string& k) {
    for (const auto& [n, v] : stats)
      if (n == k) return v;
    return -1.0;
  };
  EXPECT_FLOAT_EQ(static_cast<float>(stat("step_m")), 0.02f) << "absolute units";
  EXPECT_GE(stat("longest_root_m"), 1.0);
  EXPECT_LT(stat("longest_root_m"), 1.0 + 2 * 0.02 * 2) << "one iteration past maxIvyLength at most";
  EXPECT_EQ(stat("deaths_collision"), 0.0) << "Blender's collision never kills";
  EXPECT_GT(stat("roots"), 10.0) << "it branches";
  EXPECT_GT(p.leaf_count(), 100u);
}

// Many branches per iteration multiplied the roots every iteration: a million per step on the wall took
// minutes and gigabytes. No root starts past max_roots, and a million per step is refused.
TEST(IvyParams, RootsStopBranchingAtMaxRoots) {
  const Scene wall = load_scene("wall");
  const SceneQuery q(wall, {.build_sdf = false});
  std::vector<std::pair<std::string, double>> stats;
  const Plant p = test::grow("ivy", wall, q, {"branches_per_step=1000", "max_roots=40"}, 0, 1, 60, &stats);
  double roots = -1.0;
  for (const auto& [n, v] : stats)
    if (n == "roots") roots = v;
  EXPECT_EQ(roots, 40.0);
  EXPECT_EQ(p.validate(), "");
  Params params = default_params(find_algorithm("ivy"));
  EXPECT_NE(test::error_of([&] { params.set_assignment("branches_per_step=1000000"); }).find("branches_per_step"),
            std::string::npos);
}

TEST(IvyParams, PresetDefaultsGiveWayToExplicitValues) {
  Params p = default_params(find_algorithm("ivy"));
  EXPECT_DOUBLE_EQ(p.real("ivy_size"), 0.005);
  p.set("ivy_size", "0.03");
  p.set("preset", "blender");
  EXPECT_DOUBLE_EQ(p.real("ivy_size"), 0.03) << "set before the preset, still wins";
  EXPECT_DOUBLE_EQ(p.real("max_float_length"), 0.5);
  EXPECT_EQ(p.text("units"), "absolute");
  p.set("preset", "luft");
  EXPECT_DOUBLE_EQ(p.real("max_float_length"), 0.1);
  EXPECT_EQ(p.to_json()["units"], "relative") << "the record shows effective values";
}

TEST(IvyParams, AllZeroDirectionWeightsAreRejected) {
  const Scene scene = load_scene("wall");
  Params p = default_params(find_algorithm("ivy"));
  p.set("primary_weight", "0");
  p.set("random_weight", "0");
  p.set("adhesion_weight", "0");
  EXPECT_THROW(ivy::make_config(p, scene), InputError);
}

}  // namespace
}  // namespace growbench
