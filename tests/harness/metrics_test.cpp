#include "harness/output/metrics.hpp"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>
#include <glm/gtc/quaternion.hpp>

#include "harness/output/mesher.hpp"
#include "scenes/geometry.hpp"
#include "scenes/scene_library.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

using test::scene_with;

TriangleMesh unit_quad() {  // the square [0,1] x [0,1] at z = 0, open
  TriangleMesh q;
  q.name = "quad";
  q.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  q.triangles = {{0, 1, 2}, {0, 2, 3}};
  return q;
}

Plant chain(std::vector<glm::vec3> pts, float radius = 0.01f) {
  Plant p;
  for (std::size_t i = 0; i < pts.size(); ++i)
    p.nodes.push_back({pts[i], radius, i == 0 ? kNoParent : static_cast<std::int32_t>(i - 1), 0, 0, 0});
  return p;
}

TEST(Metrics, SegmentDistance) {
  EXPECT_NEAR(geom::segment_distance({0, 0, 0}, {1, 0, 0}, {0.5f, 1, -1}, {0.5f, 1, 1}), 1.0f,
              1e-6f);                                                                            // skew, crossing above
  EXPECT_NEAR(geom::segment_distance({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}), 1.0f, 1e-6f);  // collinear gap
  EXPECT_NEAR(geom::segment_distance({0, 0, 0}, {1, 0, 0}, {0, 0.5f, 0}, {1, 0.5f, 0}), 0.5f, 1e-6f);  // parallel
  EXPECT_NEAR(geom::segment_distance({0, 0, 0}, {0, 0, 0}, {1, 1, 0}, {1, 1, 0}), std::sqrt(2.0f), 1e-6f);
}

// Known distances from segments to the triangle (0,0,0), (1,0,0), (0,1,0) in z = 0.
TEST(Geometry, SegmentTriangleDistance) {
  const glm::vec3 t[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_FLOAT_EQ(geom::segment_triangle_distance({0.2f, 0.2f, -1}, {0.2f, 0.2f, 1}, t), 0.0f);  // through the face
  EXPECT_NEAR(geom::segment_triangle_distance({0.2f, 0.2f, 0.5f}, {0.3f, 0.3f, 2}, t), 0.5f, 1e-6f);  // end above
  // Across the plane beside the triangle, parallel to its hypotenuse at 0.5 / sqrt(2) beyond it.
  EXPECT_NEAR(geom::segment_triangle_distance({1.5f, 0, -1}, {0, 1.5f, 1}, t), 0.5f / std::sqrt(2.0f), 1e-6f);
  // Skew over the edge x = 0: the edge is closest, at height 0.3 and 0.2 outside.
  EXPECT_NEAR(geom::segment_triangle_distance({-0.2f, -1, 0.3f}, {-0.2f, 2, 0.3f}, t), std::sqrt(0.13f), 1e-6f);
  // In the triangle's plane, outside it: its nearer end to the vertex (1, 0, 0).
  EXPECT_NEAR(geom::segment_triangle_distance({2, 0, 0}, {3, 0, 0}, t), 1.0f, 1e-6f);
  // In its plane, crossing it: zero.
  EXPECT_FLOAT_EQ(geom::segment_triangle_distance({-1, 0.25f, 0}, {2, 0.25f, 0}, t), 0.0f);
}

TEST(Metrics, CountsLengthOrderDepthBox) {
  Plant p = chain({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}});
  p.nodes.push_back({{1, 1, 0}, 0.01f, 1, 1, 1, 0});
  const Scene s = scene_with(unit_quad());
  SceneQuery q(s, {.build_sdf = false});
  const auto m = compute_metrics(p, q);
  EXPECT_EQ(m["nodes"], 4);
  EXPECT_EQ(m["segments"], 3);
  EXPECT_NEAR(m["total_length_m"].get<double>(), 3.0, 1e-6);
  EXPECT_EQ(m["max_branch_order"], 1);
  EXPECT_EQ(m["max_depth"], 2);
  EXPECT_EQ(m["bbox_max"][1], 2.0);
}

TEST(Metrics, CoverageOfAStripAcrossAQuad) {
  // A segment along y = 0.5 covers the strip |y - 0.5| <= d of the unit square: a fraction 2d.
  const Scene s = scene_with(unit_quad());
  SceneQuery q(s, {.build_sdf = false});
  MetricOptions o;
  o.coverage_distance = 0.1f;
  o.coverage_samples = 20000;
  const auto m = compute_metrics(chain({{-1, 0.5f, 0}, {0.5f, 0.5f, 0}, {2, 0.5f, 0}}), q, o);
  EXPECT_NEAR(m["coverage"].get<double>(), 0.2, 5 * std::sqrt(0.2 * 0.8 / 20000));
}

TEST(Metrics, AdhesionAndPenetration) {
  // A 2 m box: top face at y = 1. Nodes at 0.01, 0.03, 0.1 above it, and one inside.
  const Scene s = scene_with(geom::make_box("box", {-1, -1, -1}, {1, 1, 1}));
  SceneQuery q(s);
  const Plant p = chain({{0, 1.01f, 0}, {0, 1.03f, 0}, {0, 1.1f, 0}, {0, 0.5f, 0}});
  const auto m = compute_metrics(p, q);
  EXPECT_NEAR(m["adhesion_mean_m"].get<double>(), (0.01 + 0.03 + 0.1 + 0.5) / 4.0, 1e-5);
  EXPECT_NEAR(m["adhesion_median_m"].get<double>(), 0.065, 1e-5);
  EXPECT_NEAR(m["attached_fraction"].get<double>(), 0.25, 1e-9);  // only 0.01 is within 0.02
  EXPECT_NEAR(m["penetration_nodes"].get<double>(), 0.25, 1e-9);
  // Segment samples at 1/4, 1/2, 3/4: those of the last segment (1.1 -> 0.5) sit at y = 0.95, 0.8, 0.65,
  // all inside; the first two segments stay above the box.
  EXPECT_NEAR(m["penetration_samples"].get<double>(), 3.0 / 9.0, 1e-9);
}

TEST(Metrics, SelfIntersectionOfCrossingBranches) {
  const Scene s = scene_with(unit_quad());
  SceneQuery q(s, {.build_sdf = false});
  Plant p = chain({{-1, 0, 0}, {0, 0, 0}, {1, 0, 0}}, 0.02f);
  const Plant other = chain({{0, -1, 0.01f}, {0, 1, 0.01f}}, 0.02f);  // crosses 1 cm above, radii sum 4 cm
  for (auto n : other.nodes) {
    if (n.parent != kNoParent) n.parent += 3;
    p.nodes.push_back(n);
  }
  auto m = compute_metrics(p, q);
  EXPECT_EQ(m["self_intersections"], 2);  // the crossing segment meets both segments of the first chain
  EXPECT_NEAR(m["self_intersection_fraction"].get<double>(), 1.0, 1e-9);
  for (auto& n : p.nodes)
    if (n.position.z > 0.0f) n.position.z = 0.5f;  // lift the second branch clear
  m = compute_metrics(p, q);
  EXPECT_EQ(m["self_intersections"], 0);
  // A straight chain never intersects itself (neighbours are excluded even at a thick radius).
  EXPECT_EQ(
      compute_metrics(chain({{0, 0, 0}, {0, 0.01f, 0}, {0, 0.02f, 0}, {0, 0.03f, 0}}, 0.5f), q)["self_intersections"],
      0);
}

// A tangle with thin and thick segments of mixed lengths, and leaves of mixed sizes: the kd-tree searches
// (each pair judged once, from its larger side; the first overlapping leaf ends a search) must count
// exactly what comparing every pair counts.
TEST(Metrics, SelfIntersectionAndLeafOverlapMatchAllPairs) {
  const Scene s = scene_with(unit_quad());
  SceneQuery q(s, {.build_sdf = false});
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Plant p;
  p.nodes.push_back({{0.5f, 0.5f, 0.5f}, 0.01f, kNoParent, 0, 0, 0});
  for (int i = 1; i < 700; ++i) {
    const auto parent = static_cast<std::int32_t>(u(rng) * static_cast<float>(i)) % i;
    const glm::vec3 dir = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f) + glm::vec3(1e-3f));
    const float len = u(rng) < 0.1f ? 0.25f : 0.02f + 0.05f * u(rng);
    const float r = u(rng) < 0.05f ? 0.06f : 0.001f + 0.004f * u(rng);
    glm::vec3 pos =
        glm::clamp(p.nodes[static_cast<std::size_t>(parent)].position + len * dir, glm::vec3(0.0f), glm::vec3(1.0f));
    p.nodes.push_back({pos, r, parent, 0, 0, 0});
  }
  for (int i = 0; i < 400; ++i) {
    const glm::vec3 axis = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f) + glm::vec3(1e-3f));
    const glm::quat turn = glm::angleAxis(6.2831853f * u(rng), axis);
    p.organs.push_back(
        {{u(rng), u(rng), u(rng)}, turn, u(rng) < 0.1f ? 0.3f : 0.05f + 0.1f * u(rng), OrganKind::Leaf, 0});
  }

  const auto& n = p.nodes;
  auto up_of = [&](std::int32_t v) { return v == kNoParent ? kNoParent : n[static_cast<std::size_t>(v)].parent; };
  auto neighbours = [&](std::int32_t x, std::int32_t y) {
    const std::int32_t X[3] = {x, up_of(x), up_of(up_of(x))}, Y[3] = {y, up_of(y), up_of(up_of(y))};
    for (const auto a : X)
      for (const auto b : Y)
        if (a != kNoParent && a == b) return true;
    return false;
  };
  std::size_t pairs = 0;
  std::vector<int> involved(n.size(), 0);
  for (std::int32_t k = 1; k < static_cast<std::int32_t>(n.size()); ++k)
    for (std::int32_t l = k + 1; l < static_cast<std::int32_t>(n.size()); ++l) {
      if (neighbours(k, l)) continue;
      const auto& a = n[static_cast<std::size_t>(k)];
      const auto& b = n[static_cast<std::size_t>(l)];
      const float d = geom::segment_distance(n[static_cast<std::size_t>(a.parent)].position, a.position,
                                             n[static_cast<std::size_t>(b.parent)].position, b.position);
      if (d < a.radius + b.radius) {
        ++pairs;
        involved[static_cast<std::size_t>(k)] = involved[static_cast<std::size_t>(l)] = 1;
      }
    }
  // Every pair of leaves, every pair of their blades' triangles.
  const TriangleMesh shape = builtin_organ_shape("leaf").mesh;
  std::size_t overlapping = 0;
  for (std::size_t i = 0; i < p.organs.size(); ++i) {
    bool meets = false;
    for (std::size_t j = 0; j < p.organs.size() && !meets; ++j) {
      if (i == j) continue;
      for (const auto& ta : shape.triangles)
        for (const auto& tb : shape.triangles) {
          glm::vec3 a[3], b[3];
          for (int k = 0; k < 3; ++k) {
            a[k] = organ_point(p.organs[i], shape.vertices[ta[k]]);
            b[k] = organ_point(p.organs[j], shape.vertices[tb[k]]);
          }
          meets = meets || geom::triangles_overlap(a, b);
        }
    }
    overlapping += meets ? 1 : 0;
  }
  ASSERT_GT(pairs, 20u);  // the tangle does cross itself, thick and thin
  ASSERT_GT(overlapping, 20u);
  ASSERT_LT(overlapping, p.organs.size());

  const auto m = compute_metrics(p, q);
  EXPECT_EQ(m["self_intersections"], pairs);
  EXPECT_NEAR(m["self_intersection_fraction"].get<double>(),
              static_cast<double>(std::count(involved.begin(), involved.end(), 1)) / static_cast<double>(n.size() - 1),
              1e-12);
  EXPECT_NEAR(m["leaf_overlap"].get<double>(), static_cast<double>(overlapping) / static_cast<double>(p.organs.size()),
              1e-12);
  // The same figures when the search reads the segments in space order, as it does for large plants.
  MetricOptions spatial;
  spatial.space_order_from = 0;
  const auto ms = compute_metrics(p, q, spatial);
  EXPECT_EQ(ms, m) << nlohmann::json::diff(m, ms).dump();
}

TEST(Metrics, LeafOverlapAndLightExposure) {
  const Scene wall = load_scene("wall");  // sun from the front (+z); the wall fills z in [-0.1, 0.1]
  SceneQuery q(wall);
  Plant p = chain({{0, 0.5f, 0.3f}, {0, 1, 0.3f}});
  const glm::quat up(1, 0, 0, 0);
  p.organs = {{{0, 1, 0.3f}, up, 0.1f, OrganKind::Leaf, 1},
              {{0, 1, 0.32f}, up, 0.1f, OrganKind::Leaf, 1},   // overlaps the first
              {{0, 1, -0.4f}, up, 0.1f, OrganKind::Leaf, 1}};  // behind the wall: shaded, alone
  const auto m = compute_metrics(p, q);
  EXPECT_NEAR(m["leaf_overlap"].get<double>(), 2.0 / 3.0, 1e-9);
  EXPECT_NEAR(m["leaf_light_exposure"].get<double>(), 2.0 / 3.0, 1e-9);
  EXPECT_EQ(m["leaves"], 3);
}

}  // namespace
}  // namespace growbench

namespace growbench {
namespace {

// A leaf shades another when it lies on the second's ray to the sun, and so does a branch; the
// scene-only figure sees neither.
TEST(Metrics, LightExposureCountsThePlantsOwnShade) {
  const Scene wall = load_scene("wall");  // sun from the front (+z)
  SceneQuery q(wall);
  const glm::vec3 sun = wall.light.towards({0, 0, 0});
  const glm::quat flat(1, 0, 0, 0);  // blade along +z, upper side +y
  Organ low{{0, 1, 0.5f}, flat, 0.1f, OrganKind::Leaf, 0};
  const glm::vec3 from = leaf_centre(low) + 1e-3f * leaf_normal(low);
  const glm::vec3 above = from + 0.2f * sun;  // where the upper leaf's centre sits on that ray
  Organ high{above - glm::vec3(0, 0, 0.05f), flat, 0.1f, OrganKind::Leaf, 0};
  Plant p = chain({{1, 0.5f, 0.5f}, {1, 1, 0.5f}});
  p.organs = {low, high};
  auto m = compute_metrics(p, q);
  EXPECT_NEAR(m["leaf_light_exposure_scene"].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(m["leaf_light_exposure"].get<double>(), 0.5, 1e-12) << "the upper leaf shades the lower";
  // A thick branch across the ray instead of the upper leaf.
  const glm::vec3 across = glm::normalize(glm::cross(sun, glm::vec3(0, 1, 0)));
  p = chain({above - 0.3f * across, above + 0.3f * across}, 0.02f);
  p.organs = {low};
  m = compute_metrics(p, q);
  EXPECT_NEAR(m["leaf_light_exposure_scene"].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(m["leaf_light_exposure"].get<double>(), 0.0, 1e-12) << "the branch shades the leaf";
  // Moved aside, it does not.
  p = chain({above - 0.3f * across + glm::vec3(0, 0.2f, 0), above + 0.3f * across + glm::vec3(0, 0.2f, 0)}, 0.02f);
  p.organs = {low};
  EXPECT_NEAR(compute_metrics(p, q)["leaf_light_exposure"].get<double>(), 1.0, 1e-12);
}

}  // namespace
}  // namespace growbench
