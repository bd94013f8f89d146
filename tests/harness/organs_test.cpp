// Organ shapes, the organ pass (variation, avoid placement) and what the mesher makes of them.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>

#include <glm/gtc/quaternion.hpp>
#define GLM_ENABLE_EXPERIMENTAL  // glm::rotation
#include <glm/gtx/quaternion.hpp>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "algorithms/organ_shapes.hpp"
#include "core/random.hpp"
#include "harness/organs/placement.hpp"
#include "harness/output/exporters.hpp"
#include "harness/output/mesher.hpp"
#include "scenes/geometry.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

float max_radial(const OrganShape& s) {
  float r = 0.0f;
  for (const auto& v : s.mesh.vertices) r = std::max(r, std::hypot(v.x, v.y));
  return r;
}

TEST(OrganShapes, BuiltinsHaveTheirSizeAndSettings) {
  const OrganShape leaf = builtin_organ_shape("leaf");
  EXPECT_EQ(leaf.mesh.triangles.size(), 2u);
  EXPECT_EQ(leaf.box_min, glm::vec3(-0.25f, 0.0f, 0.0f));
  EXPECT_EQ(leaf.box_max, glm::vec3(0.25f, 0.0f, 1.0f));
  for (const auto& n : leaf.normals) EXPECT_EQ(n, glm::vec3(0, 1, 0));  // the upper side, +Y
  // A blossom is 1 across at most, its petals tilted forward by `cup`; five petals of ten triangles.
  const OrganShape open = builtin_organ_shape("blossom");
  EXPECT_EQ(open.mesh.triangles.size(), 50u);
  EXPECT_LE(max_radial(open), 0.5f);
  EXPECT_GE(max_radial(open), 0.48f);
  const OrganShape half = builtin_organ_shape("half_bloom");
  EXPECT_LT(max_radial(half), 0.5f * max_radial(open) * 1.5f);
  EXPECT_GT(half.box_max.z, open.box_max.z);  // cupped forward
  EXPECT_EQ(builtin_organ_shape("blossom:petals=7,cup=0").mesh.triangles.size(), 70u);
  EXPECT_NEAR(builtin_organ_shape("blossom:cup=0").box_max.z, 0.04f, 1e-6f);  // flat: the petals' plane
  const OrganShape bud = builtin_organ_shape("bud");
  EXPECT_FLOAT_EQ(bud.box_min.z, 0.0f);
  EXPECT_FLOAT_EQ(bud.box_max.z, 1.0f);
  EXPECT_TRUE(bud.mesh.is_closed());
  EXPECT_TRUE(open.has_color && bud.has_color && !leaf.has_color);
  // Bad names and settings name what was asked and what is allowed.
  EXPECT_NE(test::error_of([] {
              builtin_organ_shape("rose", "organ_k");
            }).find("organ_k: unknown organ shape 'rose'; expected one of leaf, blossom, half_bloom, bud"),
            std::string::npos);
  EXPECT_NE(test::error_of([] {
              builtin_organ_shape("blossom:petals=40");
            }).find("'blossom:petals=40': petals must be in [3, 12], got 40"),
            std::string::npos);
  EXPECT_NE(test::error_of([] { builtin_organ_shape("bud:petals=5"); }).find("unknown setting 'petals'"),
            std::string::npos);
  EXPECT_NE(test::error_of([] { builtin_organ_shape("leaf:width"); }).find("expected settings as key=number"),
            std::string::npos);
}

Organ organ_at(glm::vec3 p, float size, OrganKind kind = OrganKind::Leaf, glm::quat q = glm::quat(1, 0, 0, 0)) {
  Organ o;
  o.position = p;
  o.size = size;
  o.kind = kind;
  o.orientation = q;
  return o;
}

OrganOptions options(std::vector<std::string> set) {
  return read_organ_options(set);
}

// Whether two kept organs' triangles meet, by the leaf_overlap metric's own test. Organs of size s lie
// within s of their position, so farther pairs are skipped.
bool meet(const OrganShapes& shapes, const Organ& a, const Organ& b) {
  if (glm::length(a.position - b.position) > a.size + b.size) return false;
  for (const auto& t : shapes.of(a).mesh.triangles)
    for (const auto& u : shapes.of(b).mesh.triangles) {
      const glm::vec3 ta[3] = {organ_point(a, shapes.of(a).mesh.vertices[t.x]),
                               organ_point(a, shapes.of(a).mesh.vertices[t.y]),
                               organ_point(a, shapes.of(a).mesh.vertices[t.z])};
      const glm::vec3 tb[3] = {organ_point(b, shapes.of(b).mesh.vertices[u.x]),
                               organ_point(b, shapes.of(b).mesh.vertices[u.y]),
                               organ_point(b, shapes.of(b).mesh.vertices[u.z])};
      if (geom::triangles_overlap(ta, tb)) return true;
    }
  return false;
}

TEST(OrganPlacement, ALeafThatDoesNotFitFallsBackOrIsDropped) {
  Plant p;
  p.organs.push_back(organ_at({0, 0, 0}, 1.0f));
  // Pointing back at the first from z = 1.3, in its plane: it reaches z = 0.3, into the first blade; at a
  // quarter of its size it reaches only z = 1.05, past the first's tip.
  const glm::quat back = glm::angleAxis(glm::radians(180.0f), glm::vec3(0, 1, 0));
  p.organs.push_back(organ_at({0, 0, 1.3f}, 1.0f, OrganKind::Leaf, back));
  p.organs.push_back(organ_at({0, 0, 0}, 1.0f));  // the first again: no size of it fits
  Plant free = p;
  EXPECT_EQ(place_organs(free, options({})).placed, 3u);
  // Without turns and shrinking, only the fallback is tried.
  const PlacementCounts c =
      place_organs(p, options({"placement=avoid", "fallback_leaf=0.25", "turn_deg=0", "shrink=1"}));
  EXPECT_EQ(c.placed, 1u);
  EXPECT_EQ(c.fallen_back, 1u);
  EXPECT_EQ(c.dropped, 1u);
  ASSERT_EQ(p.organs.size(), 2u);
  EXPECT_FLOAT_EQ(p.organs[1].size, 0.25f);
  // Without a fallback the second is dropped as well.
  Plant q = free;
  EXPECT_EQ(place_organs(q, options({"placement=avoid", "fallback_leaf=0", "turn_deg=0", "shrink=1"})).dropped, 2u);
}

// Before its fallback an organ tries itself turned about its attachment point, then smaller. A branch passes
// through a blossom's petals 0.35 from its axis (as in AFlowerThroughABranchFallsBackToABud): turned 60
// degrees about a cross axis, the petals reach only about 0.3 across the branch's side and clear it; at half
// its size the blossom clears it too. Either way it stays a blossom, and the counts say so per kind.
TEST(OrganPlacement, AnOrganTriesItselfTurnedAndSmallerBeforeItsFallback) {
  Plant p;
  p.nodes.push_back({glm::vec3(0.35f, 0.0f, -0.5f), 0.01f, kNoParent, 0, 0, 0});
  p.nodes.push_back({glm::vec3(0.35f, 0.0f, 1.0f), 0.01f, 0, 0, 0, 0});
  p.organs.push_back(organ_at({0, 0, 0}, 1.0f, OrganKind::Flower));
  Plant turned = p, smaller = p;
  const PlacementCounts t = place_organs(turned, options({"placement=avoid", "turn_deg=60", "shrink=1"}));
  EXPECT_EQ(t.fallen_back, 1u);
  EXPECT_EQ(t.by_kind[static_cast<std::size_t>(OrganKind::Flower)].fallen_back, 1u);
  ASSERT_EQ(turned.organs.size(), 1u);
  EXPECT_EQ(turned.organs[0].kind, OrganKind::Flower);
  EXPECT_EQ(turned.organs[0].shape, kKindShape);
  EXPECT_FLOAT_EQ(turned.organs[0].size, 1.0f);
  EXPECT_NE(turned.organs[0].orientation, p.organs[0].orientation);
  const PlacementCounts s = place_organs(smaller, options({"placement=avoid", "turn_deg=0", "shrink=0.5"}));
  EXPECT_EQ(s.fallen_back, 1u);
  ASSERT_EQ(smaller.organs.size(), 1u);
  EXPECT_EQ(smaller.organs[0].kind, OrganKind::Flower);
  EXPECT_FLOAT_EQ(smaller.organs[0].size, 0.5f);
  // Free placement counts every organ placed, by kind.
  Plant free = p;
  EXPECT_EQ(place_organs(free, options({})).by_kind[static_cast<std::size_t>(OrganKind::Flower)].placed, 1u);
}

TEST(OrganPlacement, LeavesOfOneTuftMayShareTheirBase) {
  // Three leaves from one point, 120 degrees apart: they touch at the stem and nowhere else.
  Plant p;
  for (int k = 0; k < 3; ++k)
    p.organs.push_back(
        organ_at({0, 0, 0}, 1.0f, OrganKind::Leaf, glm::angleAxis(glm::radians(120.0f * k), glm::vec3(0, 1, 0))));
  EXPECT_EQ(place_organs(p, options({"placement=avoid"})).placed, 3u);
}

TEST(OrganPlacement, AFlowerThroughABranchFallsBackToABud) {
  // A branch passes through the blossom's petals 0.35 from its axis, outside the bud's body.
  Plant p;
  p.nodes.push_back({glm::vec3(0.35f, 0.0f, -0.5f), 0.01f, kNoParent, 0, 0, 0});
  p.nodes.push_back({glm::vec3(0.35f, 0.0f, 1.0f), 0.01f, 0, 0, 0, 0});
  p.organs.push_back(organ_at({0, 0, 0}, 1.0f, OrganKind::Flower));
  const PlacementCounts c = place_organs(p, options({"placement=avoid", "turn_deg=0", "shrink=1"}));
  EXPECT_EQ(c.fallen_back, 1u);
  ASSERT_EQ(p.organs.size(), 1u);
  EXPECT_EQ(p.organs[0].kind, OrganKind::Bud);
  EXPECT_EQ(p.organ_shapes.at(p.organs[0].shape), "bud");
  // Its own stem does not count: the same branch ending at the flower's node leaves it as it is.
  Plant own;
  own.nodes = p.nodes;
  own.organs.push_back(organ_at({0, 0, 0}, 1.0f, OrganKind::Flower));
  own.organs[0].node = 1;
  EXPECT_EQ(place_organs(own, options({"placement=avoid"})).placed, 1u);
  // fallback_flower=none drops it.
  Plant none;
  none.nodes = p.nodes;
  none.organs.push_back(organ_at({0, 0, 0}, 1.0f, OrganKind::Flower));
  EXPECT_EQ(place_organs(none, options({"placement=avoid", "fallback_flower=none", "turn_deg=0", "shrink=1"})).dropped,
            1u);
}

// An organ's stem is the chain of segments from its branch point, not only the last one: a blossom on a
// 0.01 pedicel after a 0.3 stem of thickness 0.03 (F(0.3)F(0.01)J) sits inside the stem's first capsule,
// which holds it; it was dropped while only the last segment counted as its stem. A branch from the
// branch point is not its stem: beyond the collar (as far from the joint as the blossom's node), it
// still blocks it.
TEST(OrganPlacement, AnOrgansStemIsItsChainFromTheBranchPoint) {
  const glm::quat up = glm::angleAxis(-0.5f * std::numbers::pi_v<float>, glm::vec3(1, 0, 0));  // +Z to +Y
  Plant p;
  p.nodes.push_back({glm::vec3(0.0f), 0.015f, kNoParent, 0, 0, 0});
  p.nodes.push_back({glm::vec3(0.0f, 0.3f, 0.0f), 0.015f, 0, 0, 0, 0});
  p.nodes.push_back({glm::vec3(0.0f, 0.31f, 0.0f), 0.015f, 1, 0, 0, 0});
  p.organs.push_back(organ_at({0.0f, 0.31f, 0.0f}, 0.03f, OrganKind::Flower, up));
  p.organs[0].node = 2;
  const PlacementCounts c = place_organs(p, options({"placement=avoid", "fallback_flower=none"}));
  EXPECT_EQ(c.placed, 1u);
  EXPECT_EQ(c.dropped, 0u);
  // The same pedicel from a branch point, with a side branch leaving that point through the blossom.
  Plant fork = p;
  fork.organs[0].position = {0.0f, 0.33f, 0.0f};
  fork.nodes[2].position = {0.0f, 0.33f, 0.0f};
  fork.nodes.push_back({glm::vec3(0.0f, 0.36f, 0.0f), 0.015f, 1, 1, 1, 0});
  EXPECT_EQ(place_organs(fork, options({"placement=avoid", "fallback_flower=none"})).dropped, 1u);
}

// A crowd of leaves and flowers at random, dense enough that most meet another.
Plant crowd(std::size_t n, float box) {
  Plant p;
  Rng rng(7, 1);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 at(rng.uniform(0, box), rng.uniform(0, box), rng.uniform(0, box));
    const glm::quat q =
        glm::normalize(glm::quat(static_cast<float>(rng.uniform(-1, 1)), static_cast<float>(rng.uniform(-1, 1)),
                                 static_cast<float>(rng.uniform(-1, 1)), static_cast<float>(rng.uniform(-1, 1))));
    p.organs.push_back(organ_at(at, 0.1f, i % 4 == 3 ? OrganKind::Flower : OrganKind::Leaf, q));
  }
  return p;
}

TEST(OrganPlacement, KeptOrgansNeverMeetAndTheResultIsTheSameForAnyThreadCount) {
  const Plant grown = crowd(1500, 0.6f);
  Plant one = grown, two = grown;
  PlacementCounts c1, c2;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
    c1 = place_organs(one, options({"placement=avoid"}));
  }
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
    c2 = place_organs(two, options({"placement=avoid"}));
  }
  EXPECT_EQ(one.geometry_hash(), two.geometry_hash());
  EXPECT_EQ(c1.placed, c2.placed);
  EXPECT_EQ(c1.placed + c1.fallen_back + c1.dropped, grown.organs.size());
  EXPECT_GT(c1.fallen_back, 0u);
  EXPECT_GT(c1.dropped, 0u);
  // Every pair of kept organs, by brute force with the metric's triangle test.
  const OrganShapes shapes(one);
  std::size_t meeting = 0;
  for (std::size_t i = 0; i < one.organs.size(); ++i)
    for (std::size_t j = i + 1; j < one.organs.size(); ++j) meeting += meet(shapes, one.organs[i], one.organs[j]);
  EXPECT_EQ(meeting, 0u);
  // As grown, many do.
  const OrganShapes all(grown);
  std::size_t before = 0;
  for (std::size_t i = 0; i < 300; ++i)
    for (std::size_t j = i + 1; j < grown.organs.size(); ++j) before += meet(all, grown.organs[i], grown.organs[j]);
  EXPECT_GT(before, 50u);
}

float point_to_segment(const glm::vec3& x, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 ab = b - a;
  const float l2 = glm::dot(ab, ab);
  const float t = l2 > 0.0f ? std::clamp(glm::dot(x - a, ab) / l2, 0.0f, 1.0f) : 0.0f;
  return glm::length(x - (a + t * ab));
}

// The branches as the definition reads them, each walk done again for every question.
struct ReferenceBranches {
  const Plant& p;

  [[nodiscard]] const PlantNode& node(std::int32_t i) const { return p.nodes[static_cast<std::size_t>(i)]; }
  [[nodiscard]] long children(std::int32_t up) const {
    return std::count_if(p.nodes.begin(), p.nodes.end(), [&](const auto& n) { return n.parent == up; });
  }
  // The joint the chain through node `own` leaves (its first branch point above), or kNoParent, and the
  // chain's first node.
  [[nodiscard]] std::pair<std::int32_t, std::int32_t> joint_of(std::int32_t own) const {
    std::int32_t x = own;
    while (node(x).parent != kNoParent && children(node(x).parent) == 1) x = node(x).parent;
    return {node(x).parent, x};
  }
  // The part [t0, t1] of the segment ending at node c that may block an organ at node `own`: none of the
  // segments from own up to its joint, or of those starting at own; of a segment ending or starting at the
  // joint, what lies farther from the joint than own's node by more than the segment's radius.
  [[nodiscard]] std::pair<float, float> blocking_part(std::int32_t c, std::int32_t own) const {
    if (own == kNoParent) return {0.0f, 1.0f};
    const std::int32_t joint = joint_of(own).first, up = node(c).parent;
    for (std::int32_t x = own; x != joint; x = node(x).parent)
      if (x == c) return {1.0f, 0.0f};
    if (up == own) return {1.0f, 0.0f};
    if (joint == kNoParent || (up != joint && c != joint)) return {0.0f, 1.0f};
    const float len = glm::length(node(c).position - node(up).position);
    const float r = std::max({node(up).radius, node(c).radius, 1e-4f});
    const float collar = len > 0.0f ? (glm::length(node(own).position - node(joint).position) + r) / len : 1.0f;
    return up == joint ? std::pair{collar, 1.0f} : std::pair{0.0f, 1.0f - collar};
  }
  // Whether a triangle of the organ comes within a segment's radius of its blocking part.
  [[nodiscard]] bool block(const Organ& o, const OrganShape& shape) const {
    for (std::int32_t c = 0; c < static_cast<std::int32_t>(p.nodes.size()); ++c) {
      if (node(c).parent == kNoParent) continue;
      const auto [t0, t1] = blocking_part(c, o.node);
      if (!(t0 < t1)) continue;
      const PlantNode &q = node(node(c).parent), &n = node(c);
      const float r = std::max({q.radius, n.radius, 1e-4f});
      const glm::vec3 a = glm::mix(q.position, n.position, t0), b = glm::mix(q.position, n.position, t1);
      for (const auto& t : shape.mesh.triangles) {
        const glm::vec3 v[3] = {organ_point(o, shape.mesh.vertices[t.x]), organ_point(o, shape.mesh.vertices[t.y]),
                                organ_point(o, shape.mesh.vertices[t.z])};
        // A triangle within r of the segment has a vertex within r and its longest edge of it.
        const float edge = std::max({glm::length(v[1] - v[0]), glm::length(v[2] - v[1]), glm::length(v[0] - v[2])});
        if (std::min({point_to_segment(v[0], a, b), point_to_segment(v[1], a, b), point_to_segment(v[2], a, b)}) >
            r + edge + 1e-5f)
          continue;
        if (geom::segment_triangle_distance(a, b, v) < r) return true;
      }
    }
    return false;
  }
  // The organ pointed from its joint (or its chain's first node) to its node.
  [[nodiscard]] Organ along_stem(Organ o) const {
    if (o.node == kNoParent) return o;
    const auto [joint, first] = joint_of(o.node);
    o.orientation =
        pointed_along(o.orientation, node(joint == kNoParent ? first : joint).position, node(o.node).position);
    return o;
  }
};

bool reference_triangles_meet(const OrganShapes& shapes, const Organ& a, const Organ& b) {
  const auto &ma = shapes.of(a).mesh, &mb = shapes.of(b).mesh;
  for (const auto& t : ma.triangles)
    for (const auto& u : mb.triangles) {
      const glm::vec3 ta[3] = {organ_point(a, ma.vertices[t.x]), organ_point(a, ma.vertices[t.y]),
                               organ_point(a, ma.vertices[t.z])};
      const glm::vec3 tb[3] = {organ_point(b, mb.vertices[u.x]), organ_point(b, mb.vertices[u.y]),
                               organ_point(b, mb.vertices[u.z])};
      if (geom::triangles_overlap(ta, tb)) return true;
    }
  return false;
}

// An organ's candidates in the order the definition tries them: as grown; turned by +-turn_deg about its
// X, then its Y axis; pointed along its stem, then so and turned; at `shrink` of its size; its fallback.
std::vector<Organ> reference_candidates(const Organ& grown, const OrganOptions& opt, const ReferenceBranches& b,
                                        const std::optional<Organ>& fallback) {
  std::vector<Organ> out{grown};
  auto turned = [&](const Organ& from) {
    for (const glm::vec3 axis : {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)})
      for (const double deg : {opt.turn_deg, -opt.turn_deg}) {
        Organ t = from;
        t.orientation = glm::normalize(from.orientation * glm::angleAxis(static_cast<float>(glm::radians(deg)), axis));
        out.push_back(t);
      }
  };
  if (opt.turn_deg != 0.0) {
    turned(grown);
    const Organ along = b.along_stem(grown);  // a copy: turned() adds to `out`
    out.push_back(along);
    turned(along);
  }
  if (opt.shrink < 1.0) {
    Organ s = grown;
    s.size = static_cast<float>(s.size * opt.shrink);
    out.push_back(s);
  }
  if (fallback) out.push_back(*fallback);
  return out;
}

// The avoid placement by its definition, by brute force over every pair: each organ in order takes its
// first candidate (reference_candidates) whose triangles come within no branch segment's radius (but its
// stem's, the chain from its joint, and the joint's segments' collar) and meet those of no organ kept
// before it. `blocked` counts the candidates a branch turned away.
PlacementCounts reference_placement(Plant& p, const OrganOptions& opt, std::size_t& blocked) {
  auto named = [&](const std::string& f) {
    const auto it = std::find(p.organ_shapes.begin(), p.organ_shapes.end(), f);
    if (it != p.organ_shapes.end()) return static_cast<std::uint16_t>(it - p.organ_shapes.begin());
    p.organ_shapes.push_back(f);
    return static_cast<std::uint16_t>(p.organ_shapes.size() - 1);
  };
  for (const auto* f : {&opt.fallback_flower, &opt.fallback_bud})
    if (*f != "none") named(*f);
  const OrganShapes shapes(p);
  auto fallback = [&](Organ o) -> std::optional<Organ> {
    if (o.kind == OrganKind::Leaf || o.kind == OrganKind::YoungLeaf) {
      if (!(opt.fallback_leaf > 0.0)) return std::nullopt;
      o.size = static_cast<float>(o.size * opt.fallback_leaf);
      return o;
    }
    const std::string& f = o.kind == OrganKind::Flower ? opt.fallback_flower : opt.fallback_bud;
    if (f == "none") return std::nullopt;
    o.shape = named(f);
    if (f.rfind("bud", 0) == 0) o.kind = OrganKind::Bud;
    return o;
  };
  const ReferenceBranches branches{p};
  PlacementCounts counts;
  std::vector<Organ> kept;
  for (const Organ& grown : p.organs) {
    const std::vector<Organ> candidates = reference_candidates(grown, opt, branches, fallback(grown));
    bool fitted = false;
    for (std::size_t v = 0; v < candidates.size() && !fitted; ++v) {
      const Organ& o = candidates[v];
      if (branches.block(o, shapes.of(o))) {
        ++blocked;
        continue;
      }
      const OrientedBox box = organ_box(o, shapes.of(o));
      fitted = std::none_of(kept.begin(), kept.end(), [&](const Organ& k) {
        return boxes_overlap(box, organ_box(k, shapes.of(k))) && reference_triangles_meet(shapes, o, k);
      });
      if (!fitted) continue;
      kept.push_back(o);
      ++(v == 0 ? counts.placed : counts.fallen_back);
    }
    if (!fitted) ++counts.dropped;
  }
  p.organs = std::move(kept);
  return counts;
}

// Shoots of nodes wandering through a small cube, half of them branching from the others, with leaves, young leaves,
// flowers and buds of sizes a factor of six apart on the nodes and between them, so that organs meet each other and
// branches.
Plant cluster(std::size_t organs) {
  Plant p;
  Rng rng(5, 2);
  for (int s = 0; s < 8; ++s) {
    glm::vec3 at(rng.uniform(0, 0.5), rng.uniform(0, 0.5), rng.uniform(0, 0.5));
    std::int32_t parent = kNoParent;
    if (s >= 4) {  // a branch from a node of an earlier shoot, which becomes a joint
      parent = static_cast<std::int32_t>(rng.next_u64() % p.nodes.size());
      at = p.nodes[static_cast<std::size_t>(parent)].position + 0.02f * rng.unit_vector();
    }
    for (int k = 0; k < 12; ++k) {
      p.nodes.push_back(
          {at, static_cast<float>(rng.uniform(0.002, 0.01)), parent, 0, static_cast<std::uint32_t>(s), 0});
      parent = static_cast<std::int32_t>(p.nodes.size() - 1);
      at += 0.06f * rng.unit_vector();
    }
  }
  constexpr OrganKind kinds[] = {OrganKind::Leaf, OrganKind::YoungLeaf, OrganKind::Flower, OrganKind::Bud};
  for (std::size_t i = 0; i < organs; ++i) {
    const auto node = static_cast<std::int32_t>(rng.next_u64() % p.nodes.size());
    const bool on_node = i % 3 != 0;  // the others float free, with no stem
    const glm::vec3 at = on_node ? p.nodes[static_cast<std::size_t>(node)].position
                                 : glm::vec3(rng.uniform(0, 0.5), rng.uniform(0, 0.5), rng.uniform(0, 0.5));
    const glm::quat q =
        glm::normalize(glm::quat(static_cast<float>(rng.uniform(-1, 1)), static_cast<float>(rng.uniform(-1, 1)),
                                 static_cast<float>(rng.uniform(-1, 1)), static_cast<float>(rng.uniform(-1, 1))));
    Organ o = organ_at(at, static_cast<float>(rng.uniform(0.02, 0.12)), kinds[rng.next_u64() % 4], q);
    o.node = on_node ? node : kNoParent;
    p.organs.push_back(o);
  }
  return p;
}

TEST(OrganPlacement, DecidesAsTheBruteForceDefinitionForAnyThreadCount) {
  const Plant grown = cluster(400);
  for (const auto& set :
       {std::vector<std::string>{"placement=avoid"},
        {"placement=avoid", "fallback_leaf=0.3", "fallback_flower=half_bloom", "fallback_bud=bud:width=0.15"}}) {
    SCOPED_TRACE(set.back());
    const OrganOptions opt = options(set);
    Plant reference = grown;
    std::size_t blocked = 0;
    const PlacementCounts want = reference_placement(reference, opt, blocked);
    // The cluster exercises every outcome, and branches turn some candidates away.
    EXPECT_GT(want.placed, 50u);
    EXPECT_GT(want.fallen_back, 10u);
    EXPECT_GT(want.dropped, 10u);
    EXPECT_GT(blocked, 10u);
    std::vector<std::string> hashes;
    for (const int threads : {1, 2}) {
      tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
      Plant placed = grown;
      const PlacementCounts got = place_organs(placed, opt);
      EXPECT_EQ(got.placed, want.placed) << threads;
      EXPECT_EQ(got.fallen_back, want.fallen_back) << threads;
      EXPECT_EQ(got.dropped, want.dropped) << threads;
      EXPECT_EQ(placed.organ_shapes, reference.organ_shapes) << threads;
      // The same organs, each as the definition takes it, with the same quaternions.
      ASSERT_EQ(placed.organs.size(), reference.organs.size()) << threads;
      for (std::size_t k = 0; k < placed.organs.size(); ++k) {
        const Organ &a = placed.organs[k], &b = reference.organs[k];
        EXPECT_TRUE(a.position == b.position && a.size == b.size && a.shape == b.shape && a.kind == b.kind &&
                    a.node == b.node && a.orientation == b.orientation)
            << "organ " << k << ", " << threads << " threads";
      }
      hashes.push_back(placed.geometry_hash());
    }
    EXPECT_EQ(hashes[0], hashes[1]);  // bit for bit the same for 1 and 2 threads
  }
}

TEST(OrganPlacement, AnEmptyPlantStaysEmpty) {
  Plant p;
  const PlacementCounts c = place_organs(p, options({"placement=avoid"}));
  EXPECT_EQ(c.placed + c.fallen_back + c.dropped, 0u);
  EXPECT_TRUE(p.organs.empty());
  EXPECT_EQ(p.organ_shapes, std::vector<std::string>{"bud"});  // the flowers' fallback, named as always
}

TEST(OrganVariation, DrawsStayInTheirRangesAndRepeat) {
  Plant p = crowd(400, 1.0f);
  const auto opt = options({"scale_min=0.5", "scale_max=1.5", "roll_deg=30", "tilt_deg=10", "color_jitter=0.2"});
  Plant a = p, b = p;
  vary_organs(a, opt, 3);
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
    vary_organs(b, opt, 3);
  }
  EXPECT_EQ(a.geometry_hash(), b.geometry_hash());
  Plant c = p;
  vary_organs(c, opt, 4);
  EXPECT_NE(a.geometry_hash(), c.geometry_hash());
  float lo = 2.0f, hi = 0.0f;
  for (std::size_t i = 0; i < a.organs.size(); ++i) {
    const float s = a.organs[i].size / p.organs[i].size;
    lo = std::min(lo, s);
    hi = std::max(hi, s);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(a.organs[i].tint[k], 0.8f - 1e-6f);
      EXPECT_LE(a.organs[i].tint[k], 1.2f + 1e-6f);
    }
    // The roll turns about the stem: the blade's direction moves by at most the tilt.
    const glm::vec3 h0 = p.organs[i].orientation * glm::vec3(0, 0, 1),
                    h1 = a.organs[i].orientation * glm::vec3(0, 0, 1);
    EXPECT_LE(std::acos(std::clamp(glm::dot(h0, h1), -1.0f, 1.0f)), glm::radians(10.0f) + 1e-3f);
  }
  EXPECT_LT(lo, 0.6f);
  EXPECT_GT(hi, 1.4f);
  EXPECT_TRUE(a.validate().empty()) << a.validate();
}

TEST(OrganVariation, AlternateBloomTurnsEverySecondBlossom) {
  Plant p;
  for (int i = 0; i < 5; ++i) p.organs.push_back(organ_at({float(i), 0, 0}, 0.1f, OrganKind::Flower));
  p.organs.insert(p.organs.begin() + 1, organ_at({9, 0, 0}, 0.1f, OrganKind::Leaf));
  vary_organs(p, options({"alternate_bloom=true"}), 1);
  const OrganShapes shapes(p);
  std::vector<std::string> names;
  for (const auto& o : p.organs) names.push_back(shapes.of(o).name);
  EXPECT_EQ(names, (std::vector<std::string>{"blossom", "leaf", "half_bloom", "blossom", "half_bloom", "blossom"}));
}

TEST(OrganOptions, BadValuesNameTheKey) {
  EXPECT_NE(test::error_of([] { options({"placement=tidy"}); }).find("placement"), std::string::npos);
  EXPECT_NE(test::error_of([] {
              options({"scale_min=2", "scale_max=1"});
            }).find("scale_min 2 is above scale_max 1"),
            std::string::npos);
  EXPECT_NE(test::error_of([] {
              options({"fallback_flower=tulip"});
            }).find("organ option fallback_flower: unknown organ shape 'tulip'"),
            std::string::npos);
  EXPECT_FALSE(options({}).active());
  EXPECT_TRUE(options({"placement=avoid"}).active());
}

TEST(OrganMesher, ColouredOrgansGiveEveryVertexAColour) {
  Plant plain;
  plain.organs.push_back(organ_at({0, 0, 0}, 1.0f));
  EXPECT_TRUE(mesh_plant(plain).colors.empty());  // plain leaves: no colours written
  Plant p;
  p.nodes.push_back({glm::vec3(0.0f), 0.01f, kNoParent, 0, 0, 0});
  p.nodes.push_back({glm::vec3(0, 1, 0), 0.01f, 0, 0, 0, 0});
  p.organs.push_back(organ_at({0, 1, 0}, 0.2f, OrganKind::Flower));
  p.organs.push_back(organ_at({0, 1, 0}, 0.2f));
  p.organs[1].tint = glm::vec3(0.5f, 1.0f, 1.0f);
  const OutputMesh m = mesh_plant(p);
  ASSERT_EQ(m.colors.size(), m.positions.size());
  const glm::vec3 bark = srgb_to_linear(material_srgb("bark"));
  const glm::vec3 leaf = srgb_to_linear(organ_kind_srgb(OrganKind::Leaf)) * glm::vec3(0.5f, 1.0f, 1.0f);
  const glm::vec3 petal = srgb_to_linear(builtin_organ_shape("blossom").srgb);
  const auto& g = m.groups;
  ASSERT_EQ(g.size(), 3u);
  EXPECT_EQ(m.colors[m.triangles[g[0].first_triangle].x], bark);
  EXPECT_EQ(m.colors[m.triangles[g[1].first_triangle].x], leaf);
  EXPECT_EQ(m.colors[m.triangles[g[2].first_triangle].x], petal);
  EXPECT_EQ(g[2].triangle_count, 50u);
}

TEST(OrganSnapshot, ShapesAndTintsSurviveTheRoundTrip) {
  const auto dir = test::temp_dir("organ_snapshot");
  Plant p;
  p.organs.push_back(organ_at({0, 0, 0}, 0.3f, OrganKind::Flower));
  p.organs.push_back(organ_at({1, 0, 0}, 0.2f, OrganKind::Bud));
  p.organ_shapes = {"half_bloom", "bud:width=0.2"};
  p.organs[0].shape = 0;
  p.organs[0].tint = glm::vec3(1.1f, 0.9f, 1.0f);
  const std::string path = (dir / "p.gbplant").string();
  write_plant_snapshot(path, p);
  const Plant q = read_plant_snapshot(path);
  EXPECT_EQ(q.organ_shapes, p.organ_shapes);
  EXPECT_EQ(q.organs[0].shape, 0u);
  EXPECT_EQ(q.organs[1].shape, kKindShape);
  EXPECT_EQ(q.organs[0].tint, p.organs[0].tint);
  EXPECT_EQ(q.geometry_hash(), p.geometry_hash());
  // A shape index past the names is the plant's own check, through the reader.
  Plant bad = p;
  bad.organs[1].shape = 7;
  EXPECT_NE(bad.validate().find("organ 1 has shape 7 of 2"), std::string::npos);
}

}  // namespace
}  // namespace growbench
