#include "harness/organs/placement.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <span>

#include <glm/gtc/quaternion.hpp>
#define GLM_ENABLE_EXPERIMENTAL  // glm::rotation (the least rotation between two vectors)
#include <glm/gtx/quaternion.hpp>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_for_each.h>

#include "core/kdtree.hpp"
#include "core/random.hpp"
#include "scenes/geometry.hpp"

namespace growbench {
namespace {

// The random stream of the organ pass: apart from every algorithm's, so a draw here never repeats one
// that grew the plant.
constexpr std::uint64_t kOrganStream = 0x6f7267616e73ull;  // "organs"

std::uint16_t shape_index(Plant& plant, const std::string& name) {
  const auto it = std::find(plant.organ_shapes.begin(), plant.organ_shapes.end(), name);
  if (it != plant.organ_shapes.end()) return static_cast<std::uint16_t>(it - plant.organ_shapes.begin());
  plant.organ_shapes.push_back(name);
  return static_cast<std::uint16_t>(plant.organ_shapes.size() - 1);
}

bool is_blossom(const Plant& plant, const Organ& o) {
  if (o.kind != OrganKind::Flower) return false;
  if (o.shape == kKindShape) return true;  // a flower's default shape
  return plant.organ_shapes[o.shape].rfind("blossom", 0) == 0;
}

double pad_for(const Organ& o) {
  const glm::vec3 p = glm::abs(o.position);
  return 1e-6 * o.size + 4.0 * std::numeric_limits<float>::epsilon() * std::max({p.x, p.y, p.z, o.size});
}

// Whether the segment (a, b) comes closer than r to the box [-h, h], both in the box's frame: the
// distance is a convex function of the segment's parameter, minimised by golden-section search. Each
// step keeps the lower of its two points, so the least distance found is the least of all evaluated:
// the search can stop at the first below r, with the verdict the full search gives.
bool segment_near_box(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& h, double r) {
  auto dist = [&](double t) {
    const glm::dvec3 p = a + t * (b - a);
    return glm::length(glm::max(glm::abs(p) - h, glm::dvec3(0.0)));
  };
  if (dist(0.0) < r || dist(1.0) < r) return true;
  double lo = 0.0, hi = 1.0;
  constexpr double g = 0.6180339887498949;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = dist(x1), f2 = dist(x2);
  for (int k = 0; k < 60 && hi - lo > 1e-9; ++k) {
    if (f1 < r || f2 < r) return true;
    if (f1 <= f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - g * (hi - lo);
      f1 = dist(x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + g * (hi - lo);
      f2 = dist(x2);
    }
  }
  return f1 < r || f2 < r;
}

// What an organ becomes when it does not fit, by kind. The fallback shapes are named in the plant
// before its shapes are resolved, so making a fallback only reads.
class Fallbacks {
 public:
  Fallbacks(Plant& plant, const OrganOptions& opt)
      : leaf_(opt.fallback_leaf), flower_(named(plant, opt.fallback_flower)), bud_(named(plant, opt.fallback_bud)) {}

  [[nodiscard]] bool exist(OrganKind kind) const {
    switch (kind) {
      case OrganKind::Leaf:
      case OrganKind::YoungLeaf:
        return leaf_ > 0.0;
      case OrganKind::Flower:
        return flower_.some;
      case OrganKind::Bud:
        return bud_.some;
    }
    return false;
  }

  // The organ as its fallback; only for a kind that has one.
  [[nodiscard]] Organ of(Organ o) const {
    if (o.kind == OrganKind::Leaf || o.kind == OrganKind::YoungLeaf) {
      o.size = static_cast<float>(o.size * leaf_);
      return o;
    }
    const Shape& s = o.kind == OrganKind::Flower ? flower_ : bud_;
    o.shape = s.index;
    if (s.is_bud) o.kind = OrganKind::Bud;
    return o;
  }

 private:
  struct Shape {
    bool some = false;
    std::uint16_t index = 0;
    bool is_bud = false;
  };
  static Shape named(Plant& plant, const std::string& f) {
    if (f == "none") return {};
    return {true, shape_index(plant, f), f.rfind("bud", 0) == 0};
  }
  double leaf_;
  Shape flower_, bud_;
};

// A candidate (an organ as grown, or its fallback) ready for the box tests: its box, and bounds that
// hold the box.
struct Probe {
  OrientedBox box;
  double reach;       // the box's bounding-sphere radius
  glm::dvec3 extent;  // the half size of the box's axis-aligned bounds
};

// The bounds reject only boxes that cannot meet; the factor covers their rounding, so they never reject
// a pair boxes_overlap keeps.
constexpr double kBoundsSlack = 1.0 + 1e-9;

// boxes_overlap's verdict, after the cheap bounds.
bool boxes_meet(const Probe& a, const Probe& b) {
  const glm::dvec3 d = a.box.centre - b.box.centre;
  const double r = (a.reach + b.reach) * kBoundsSlack;
  if (glm::dot(d, d) > r * r) return false;
  if (glm::any(glm::greaterThan(glm::abs(d), (a.extent + b.extent) * kBoundsSlack))) return false;
  return boxes_overlap(a.box, b.box);
}

bool disjoint(const Aabb& x, const Aabb& y) {
  return glm::any(glm::lessThan(x.max, y.min)) || glm::any(glm::lessThan(y.max, x.min));
}

// Shape tests for deciding an organ: whether the candidate it tries meets the candidates that earlier
// organs took. The tried one is placed once (its triangles and their bounds); a taken one's vertices are
// placed the first time it is asked for and kept under its organ, since later organs are tested against
// it again. One per thread: what is kept changes no verdict.
class ShapeTests {
 public:
  explicit ShapeTests(std::size_t organs) : at_(organs, kNone) {}

  // The candidate the next calls test; nothing is placed until a test needs it.
  void begin(const Organ& organ, const OrganShape& shape) {
    tried_ = organ;
    tried_shape_ = &shape;
    tried_placed_ = false;
  }

  // Whether the tried candidate's shape and `other`'s (what organ `owner` took) intersect, triangle by
  // triangle, as the leaf_overlap metric tests them (geom::triangles_overlap on the triangles
  // organ_point places): organs that only touch, such as leaves of one tuft sharing their base, do not.
  // Only triangles whose bounds meet the other organ's are paired: disjoint bounds cannot hold a shared
  // point, so this changes no verdict.
  bool meets(std::uint32_t owner, const Organ& other, const OrganShape& shape) {
    place_tried();
    const Kept& kept = keep(owner, other, shape);
    if (disjoint(tried_all_, kept.all)) return false;
    const glm::vec3* v = &vertices_[kept.first];
    near_.clear();
    for (const auto& t : shape.mesh.triangles) {
      Tri x{{v[t.x], v[t.y], v[t.z]}, {}};
      for (const auto& p : x.v) x.box.extend(p);
      if (!disjoint(x.box, tried_all_)) near_.push_back(x);
    }
    for (const Tri& a : tri_) {
      if (disjoint(a.box, kept.all)) continue;
      for (const Tri& b : near_)
        if (!disjoint(a.box, b.box) && geom::triangles_overlap(a.v, b.v)) return true;
    }
    return false;
  }

  // Whether the tried candidate's shape meets the capsule of radius r about the segment (p, q): one of
  // its triangles comes closer than r to the segment.
  bool meets_capsule(const glm::vec3& p, const glm::vec3& q, float r) {
    place_tried();
    Aabb capsule;
    capsule.extend(glm::min(p, q) - r);
    capsule.extend(glm::max(p, q) + r);
    if (disjoint(capsule, tried_all_)) return false;
    for (const Tri& t : tri_)
      if (!disjoint(t.box, capsule) && geom::segment_triangle_distance(p, q, t.v) < r) return true;
    return false;
  }

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  struct Tri {
    glm::vec3 v[3];
    Aabb box;
  };
  struct Kept {
    std::uint32_t first;  // its vertices in vertices_
    Aabb all;
  };

  void place_tried() {
    if (tried_placed_) return;
    tried_placed_ = true;
    local_.clear();
    for (const auto& v : tried_shape_->mesh.vertices) local_.push_back(organ_point(tried_, v));
    tri_.clear();
    tried_all_ = Aabb{};
    for (const auto& t : tried_shape_->mesh.triangles) {
      Tri x{{local_[t.x], local_[t.y], local_[t.z]}, {}};
      for (const auto& p : x.v) x.box.extend(p);
      tried_all_.extend(x.box);
      tri_.push_back(x);
    }
  }

  const Kept& keep(std::uint32_t owner, const Organ& organ, const OrganShape& shape) {
    if (at_[owner] != kNone) return kept_[at_[owner]];
    Kept e{static_cast<std::uint32_t>(vertices_.size()), {}};
    for (const auto& v : shape.mesh.vertices) {
      vertices_.push_back(organ_point(organ, v));
      e.all.extend(vertices_.back());
    }
    at_[owner] = static_cast<std::uint32_t>(kept_.size());
    kept_.push_back(e);
    return kept_.back();
  }

  std::vector<std::uint32_t> at_;  // organ -> kept_, or kNone before its candidate is placed
  std::vector<Kept> kept_;
  std::vector<glm::vec3> vertices_;
  Organ tried_;
  const OrganShape* tried_shape_ = nullptr;
  bool tried_placed_ = false;
  std::vector<glm::vec3> local_;
  std::vector<Tri> tri_, near_;
  Aabb tried_all_;
};

// The branch segments, for the test that an organ's shape comes within no segment's capsule but its
// stem's (blocking_part). An organ's stem is the chain of segments from the branch point its node hangs
// from: a flower on a short, fine pedicel sits within the capsule of the pedicel's first segments, which
// hold it rather than cross it.
class Branches {
 public:
  explicit Branches(const std::vector<PlantNode>& nodes)
      : nodes_(nodes), chain_(nodes.size()), depth_(nodes.size(), 0) {
    std::vector<std::uint32_t> children(nodes.size(), 0);
    for (const auto& n : nodes)
      if (n.parent != kNoParent) ++children[static_cast<std::size_t>(n.parent)];
    // Parents precede children: a root, or a node after a branch point, starts a chain; others continue their
    // parent's.
    for (std::size_t c = 0; c < nodes.size(); ++c) {
      const std::int32_t p = nodes[c].parent;
      const auto pp = static_cast<std::size_t>(p);
      const bool starts = p == kNoParent || children[pp] > 1;
      chain_[c] = starts ? static_cast<std::uint32_t>(c) : chain_[pp];
      depth_[c] = p == kNoParent ? 0 : depth_[pp] + 1;
    }
    for (std::size_t c = 0; c < nodes.size(); ++c) {
      if (nodes[c].parent == kNoParent) continue;
      const auto& p = nodes[static_cast<std::size_t>(nodes[c].parent)];
      mid_.push_back(0.5f * (p.position + nodes[c].position));
      child_.push_back(static_cast<std::uint32_t>(c));
      reach_ = std::max(reach_, 0.5 * glm::length(glm::dvec3(p.position - nodes[c].position)) +
                                    std::max({p.radius, nodes[c].radius, 1e-4f}));
    }
    if (!mid_.empty()) tree_ = std::make_unique<Vec3Tree>(3, cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  }
  Branches(const Branches&) = delete;  // the tree refers to cloud_
  Branches& operator=(const Branches&) = delete;

  // The part of the segment ending at node c that may block an organ at node `own`, as the segment's
  // parameters [t0, t1] (empty when t0 >= t1). None of its stem: own's chain, at or above it, and the segment
  // starting at own. Of a segment of the joint own's chain leaves (ending or starting at its branch point),
  // only what lies farther from the joint than own's node by more than the segment's radius: nearer, it is
  // the collar the organ's stem leaves from, which holds the organ's base where its stem is shorter than
  // the joint is thick.
  [[nodiscard]] std::pair<float, float> blocking_part(std::uint32_t c, std::int32_t own) const {
    if (own == kNoParent) return {0.0f, 1.0f};
    const auto o = static_cast<std::size_t>(own);
    if (nodes_[c].parent == own || (chain_[c] == chain_[o] && depth_[c] <= depth_[o])) return {1.0f, 0.0f};
    const std::int32_t joint = nodes_[chain_[o]].parent;
    const bool starts = joint != kNoParent && nodes_[c].parent == joint;
    if (!starts && (joint == kNoParent || static_cast<std::int32_t>(c) != joint)) return {0.0f, 1.0f};
    const glm::vec3 j = nodes_[static_cast<std::size_t>(joint)].position;
    const float len = glm::length(nodes_[c].position - nodes_[static_cast<std::size_t>(nodes_[c].parent)].position);
    const float r = std::max({nodes_[c].radius, nodes_[static_cast<std::size_t>(nodes_[c].parent)].radius, 1e-4f});
    const float collar = len > 0.0f ? (glm::length(nodes_[o].position - j) + r) / len : 1.0f;
    return starts ? std::pair{collar, 1.0f} : std::pair{0.0f, 1.0f - collar};
  }

  // The organ's orientation pointed (pointed_along) from the joint its stem leaves, or its chain's first
  // node where there is none, to its node; unchanged for an organ on no node.
  [[nodiscard]] glm::quat along_stem(const Organ& o) const {
    if (o.node == kNoParent) return o.orientation;
    const auto n = static_cast<std::size_t>(o.node);
    const std::int32_t joint = nodes_[chain_[n]].parent;
    const glm::vec3 from = nodes_[joint == kNoParent ? chain_[n] : static_cast<std::size_t>(joint)].position;
    return pointed_along(o.orientation, from, nodes_[n].position);
  }

  // Whether a segment's blocking part (blocking_part) meets the shape of the candidate `tests`
  // tries, an organ at node `own`: its capsule meets the candidate's box, then its triangles.
  [[nodiscard]] bool block(const Probe& c, std::int32_t own, ShapeTests& tests) const {
    if (!tree_) return false;
    bool blocked = false;
    kd_visit_within(
        *tree_, glm::vec3(c.box.centre), static_cast<float>((c.reach + reach_) * (1.0 + 1e-6)),
        [&](std::uint32_t s, float) {
          const std::uint32_t ci = child_[s];
          const auto& n = nodes_[ci];
          const auto [t0, t1] = blocking_part(ci, own);
          if (!(t0 < t1)) return true;
          const auto& p = nodes_[static_cast<std::size_t>(n.parent)];
          const float r = std::max({p.radius, n.radius, 1e-4f});
          const glm::vec3 a = glm::mix(p.position, n.position, t0), b = glm::mix(p.position, n.position, t1);
          blocked = capsule_meets_box(glm::dvec3(a), glm::dvec3(b), r, c.box) && tests.meets_capsule(a, b, r);
          return !blocked;
        });
    return blocked;
  }

 private:
  const std::vector<PlantNode>& nodes_;
  std::vector<std::uint32_t> chain_;  // per node: the first node of its unbranched chain
  std::vector<std::uint32_t> depth_;  // per node: segments from its root
  std::vector<glm::vec3> mid_;        // each segment's midpoint
  std::vector<std::uint32_t> child_;  // each segment's child node
  double reach_ = 0.0;                // the farthest any segment's capsule reaches from its midpoint
  Vec3Cloud cloud_{&mid_};
  std::unique_ptr<Vec3Tree> tree_;
};

}  // namespace

OrientedBox organ_box(const Organ& organ, const OrganShape& shape) {
  const double pad = pad_for(organ);
  const glm::dmat3 r = glm::mat3_cast(organ.orientation);
  const double s = organ.size;
  OrientedBox b;
  const glm::dvec3 lo(shape.box_min), hi(shape.box_max);
  b.centre = glm::dvec3(organ.position) + r * (0.5 * s * (lo + hi));
  for (int k = 0; k < 3; ++k) b.axis[k] = r[k];
  b.half = 0.5 * s * (hi - lo) + glm::dvec3(pad);
  return b;
}

bool boxes_overlap(const OrientedBox& a, const OrientedBox& b) {
  // The separating axis test over the 15 axes (Gottschalk, Lin and Manocha): the boxes' faces and the
  // cross products of their edges. A small term absorbs near-parallel edges' rounding.
  glm::dmat3 R, AR;
  const glm::dvec3 d = b.centre - a.centre;
  const glm::dvec3 t(glm::dot(d, a.axis[0]), glm::dot(d, a.axis[1]), glm::dot(d, a.axis[2]));
  constexpr double eps = 1e-12;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      R[i][j] = glm::dot(a.axis[i], b.axis[j]);
      AR[i][j] = std::abs(R[i][j]) + eps;
    }
  for (int i = 0; i < 3; ++i)
    if (std::abs(t[i]) > a.half[i] + b.half[0] * AR[i][0] + b.half[1] * AR[i][1] + b.half[2] * AR[i][2]) return false;
  for (int j = 0; j < 3; ++j) {
    const double tj = t[0] * R[0][j] + t[1] * R[1][j] + t[2] * R[2][j];
    if (std::abs(tj) > b.half[j] + a.half[0] * AR[0][j] + a.half[1] * AR[1][j] + a.half[2] * AR[2][j]) return false;
  }
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double ra = a.half[i1] * AR[i2][j] + a.half[i2] * AR[i1][j];
      const double rb = b.half[j1] * AR[i][j2] + b.half[j2] * AR[i][j1];
      if (std::abs(t[i2] * R[i1][j] - t[i1] * R[i2][j]) > ra + rb) return false;
    }
  }
  return true;
}

glm::quat pointed_along(const glm::quat& q, const glm::vec3& from, const glm::vec3& to) {
  const glm::vec3 d = to - from;
  const float len = glm::length(d);
  if (!(len > 1e-6f * std::max(1.0f, glm::length(from)))) return q;
  const glm::vec3 axis = glm::normalize(q * glm::vec3(0, 0, 1));
  return glm::rotation(axis, d / len) * q;
}

bool capsule_meets_box(const glm::dvec3& p, const glm::dvec3& q, double r, const OrientedBox& box) {
  auto local = [&](const glm::dvec3& x) {
    const glm::dvec3 d = x - box.centre;
    return glm::dvec3(glm::dot(d, box.axis[0]), glm::dot(d, box.axis[1]), glm::dot(d, box.axis[2]));
  };
  const glm::dvec3 a = local(p), b = local(q);
  // Exact rejection first: the capsule's bounds in the box's frame miss the box.
  if (glm::any(glm::greaterThan(glm::min(a, b) - r, box.half)) ||
      glm::any(glm::lessThan(glm::max(a, b) + r, -box.half)))
    return false;
  return segment_near_box(a, b, box.half, r);
}

void vary_organs(Plant& plant, const OrganOptions& opt, std::uint64_t seed) {
  const bool vary = opt.scale_min != 1.0 || opt.scale_max != 1.0 || opt.roll_deg != 0.0 || opt.tilt_deg != 0.0 ||
                    opt.color_jitter != 0.0;
  if (vary) {
    tbb::parallel_for(std::size_t{0}, plant.organs.size(), [&](std::size_t i) {
      Organ& o = plant.organs[i];
      Rng rng(seed, kOrganStream, static_cast<std::uint64_t>(i) << 3);
      const double scale = rng.uniform(opt.scale_min, opt.scale_max);
      const double roll = glm::radians(opt.roll_deg) * rng.uniform(-1.0, 1.0);
      const double tilt = glm::radians(opt.tilt_deg) * rng.uniform(-1.0, 1.0);
      o.size = static_cast<float>(o.size * scale);
      o.orientation = glm::normalize(o.orientation * glm::angleAxis(static_cast<float>(roll), glm::vec3(0, 0, 1)) *
                                     glm::angleAxis(static_cast<float>(tilt), glm::vec3(0, 1, 0)));
      for (int c = 0; c < 3; ++c)
        o.tint[c] =
            std::clamp(static_cast<float>(o.tint[c] * (1.0 + opt.color_jitter * rng.uniform(-1.0, 1.0))), 0.0f, 4.0f);
    });
  }
  if (opt.alternate_bloom) {
    std::size_t k = 0;
    std::uint16_t half = kKindShape;
    for (auto& o : plant.organs) {
      if (!is_blossom(plant, o)) continue;
      if (k++ % 2 == 0) continue;
      if (half == kKindShape) half = shape_index(plant, "half_bloom");
      o.shape = half;
    }
  }
}

namespace {

// What each organ took: its candidate's index (0: as grown), or kDropped.
constexpr std::uint8_t kGrown = 0, kDropped = 0xFF;

// An organ's candidates, in the order they are tried: as grown; turned about its attachment point by
// +-turn_deg about its two cross axes (a blossom tipped off a neighbour, a leaf lifted off a branch);
// pointed along its stem, away from the joint it leaves (the organs of one cluster fanned out, as a
// cluster's pedicels hold them, where gravity hung them together), then so and turned as before; at
// `shrink` of its size; its kind's fallback. The turns and the shrink keep the organ what it is, so they come before
// the fallback, which changes it.
class Candidates {
 public:
  Candidates(Plant& plant, const OrganOptions& opt, const Branches& branches)
      : fallbacks_(plant, opt), branches_(branches) {
    if (opt.turn_deg > 0.0) {
      const auto a = static_cast<float>(glm::radians(opt.turn_deg));
      for (const bool along : {false, true}) {
        if (along) own_.push_back({std::nullopt, 1.0f, true});
        for (const glm::vec3 axis : {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)})
          for (const float sign : {1.0f, -1.0f}) own_.push_back({glm::angleAxis(sign * a, axis), 1.0f, along});
      }
    }
    if (opt.shrink < 1.0) own_.push_back({std::nullopt, opt.shrink, false});
  }

  [[nodiscard]] std::uint8_t count(OrganKind kind) const {
    return static_cast<std::uint8_t>(1 + own_.size() + (fallbacks_.exist(kind) ? 1 : 0));
  }
  // Candidate v (< count) of an organ as grown.
  [[nodiscard]] Organ of(Organ o, std::uint8_t v) const {
    if (v == kGrown) return o;
    if (v <= own_.size()) {
      const Own& c = own_[v - 1];
      if (c.along) o.orientation = branches_.along_stem(o);
      if (c.turn) o.orientation = glm::normalize(o.orientation * *c.turn);
      o.size = static_cast<float>(o.size * c.scale);
      return o;
    }
    return fallbacks_.of(o);
  }

 private:
  struct Own {
    std::optional<glm::quat> turn;
    double scale;
    bool along;  // first pointed along its stem
  };
  const Fallbacks fallbacks_;
  const Branches& branches_;
  std::vector<Own> own_;
};

// Each organ's own box's centre, and how far its candidates' boxes reach from it.
struct Reach {
  std::vector<glm::vec3> centres;
  std::vector<double> spread;
};

// The organs' k-d tree (their own boxes' centres) and, for each organ, the earlier organs whose
// candidates' boxes may meet its own: each organ's `spread` reaches the farthest point of any of its
// candidates' boxes, so two organs whose candidates can meet are within the sum of theirs. Organs are
// named by their place in the tree's order, where organs near in space are near in memory. The tree is
// built once, over every organ in their order; its searches decide which organs are compared.
class Neighbours {
 public:
  explicit Neighbours(Reach r) : centres_(std::move(r.centres)), spread_(std::move(r.spread)) {
    smax_ = spread_.empty() ? 0.0 : *std::max_element(spread_.begin(), spread_.end());
    tree_ = std::make_unique<Vec3Tree>(3, cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(8));
    place_.resize(centres_.size());
    for (std::size_t p = 0; p < place_.size(); ++p) place_[organ(p)] = static_cast<std::uint32_t>(p);
    find();
  }
  Neighbours(const Neighbours&) = delete;  // the tree refers to cloud_
  Neighbours& operator=(const Neighbours&) = delete;

  [[nodiscard]] std::uint32_t organ(std::size_t place) const { return tree_->vAcc[place]; }
  [[nodiscard]] std::uint32_t place(std::size_t organ) const { return place_[organ]; }

  // The places of the earlier organs near the organ at place p.
  [[nodiscard]] std::span<const std::uint32_t> of(std::size_t p) const {
    const auto& list = lists_[p / kChunk];
    const bool last = (p + 1) % kChunk == 0 || p + 1 == place_.size();
    return {list.data() + at_[p], list.data() + (last ? list.size() : at_[p + 1])};
  }

 private:
  static constexpr std::size_t kChunk = 256;

  // Each organ's search, in parallel in fixed chunks of the tree's order, each listing its organs'
  // neighbours in a buffer of its own. Every list is what its own organ's search finds, so none
  // depends on the thread count.
  void find() {
    const std::size_t n = centres_.size(), chunks = (n + kChunk - 1) / kChunk;
    at_.resize(n);
    lists_.resize(chunks);
    tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t ch) {
      auto& list = lists_[ch];
      for (std::size_t p = ch * kChunk; p < std::min(n, (ch + 1) * kChunk); ++p) {
        const std::uint32_t i = organ(p);
        at_[p] = static_cast<std::uint32_t>(list.size());
        kd_visit_within(*tree_, centres_[i], static_cast<float>((spread_[i] + smax_) * (1.0 + 1e-6)),
                        [&](std::uint32_t o, float d2) {
                          if (o >= i || std::sqrt(d2) > (spread_[i] + spread_[o]) * (1.0 + 1e-6)) return true;
                          list.push_back(place_[o]);
                          return true;
                        });
      }
    });
  }

  std::vector<glm::vec3> centres_;
  std::vector<double> spread_;
  double smax_ = 0.0;
  Vec3Cloud cloud_{&centres_};
  std::unique_ptr<Vec3Tree> tree_;
  std::vector<std::uint32_t> place_;               // organ -> its place in the tree's order
  std::vector<std::uint32_t> at_;                  // place -> its list's start in its chunk's buffer
  std::vector<std::vector<std::uint32_t>> lists_;  // by chunk of places
};

// The avoid placement. Every organ's candidates are tested lazily, only against the candidates its
// earlier neighbours took: a candidate not taken cannot block one, so the tests it would need are never
// made. An organ is decided once its earlier neighbours are, in parallel with any other organ ready.
class Placement {
 public:
  Placement(Plant& p, const OrganOptions& o, const OrganShape* custom)
      : plant_(p), branches_(p.nodes), candidates_(p, o, branches_), shapes_(p, custom), neighbours_(reach()) {}

  PlacementCounts run() {
    const std::size_t n = plant_.organs.size();
    organs_.resize(n);
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t p) { organs_[p] = plant_.organs[neighbours_.organ(p)]; });
    const std::vector<std::uint8_t> decision = decide_all();
    // The organs kept, moved down in place in their order.
    PlacementCounts counts;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t p = neighbours_.place(i);
      auto& kind = counts.by_kind[static_cast<std::size_t>(plant_.organs[i].kind)];
      if (decision[p] == kDropped) {
        ++counts.dropped;
        ++kind.dropped;
        continue;
      }
      ++(decision[p] == kGrown ? counts.placed : counts.fallen_back);
      ++(decision[p] == kGrown ? kind.placed : kind.fallen_back);
      plant_.organs[kept++] = as(p, decision[p]);
    }
    plant_.organs.resize(kept);
    return counts;
  }

 private:
  // The organ at place p as its candidate `variant`.
  [[nodiscard]] Organ as(std::uint32_t p, std::uint8_t variant) const { return candidates_.of(organs_[p], variant); }

  [[nodiscard]] Probe probe(const Organ& o) const {
    Probe p{organ_box(o, shapes_.of(o)), 0.0, glm::dvec3(0.0)};
    p.reach = glm::length(p.box.half);
    for (int k = 0; k < 3; ++k) p.extent += glm::abs(p.box.axis[k]) * p.box.half[k];
    return p;
  }

  [[nodiscard]] Reach reach() const {
    const std::size_t n = plant_.organs.size();
    Reach r{std::vector<glm::vec3>(n), std::vector<double>(n)};
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
      const Organ& o = plant_.organs[i];
      const OrientedBox own = organ_box(o, shapes_.of(o));
      r.centres[i] = glm::vec3(own.centre);
      r.spread[i] = glm::length(own.half);
      for (std::uint8_t v = 1; v < candidates_.count(o.kind); ++v) {
        const Organ f = candidates_.of(o, v);
        const OrientedBox b = organ_box(f, shapes_.of(f));
        r.spread[i] = std::max(r.spread[i], glm::length(b.centre - own.centre) + glm::length(b.half));
      }
    });
    return r;
  }

  // Every organ's decision, by place. An organ is decided when the last of its earlier neighbours is:
  // its decision reads only theirs, so each is the one visiting the organs in their order makes,
  // whichever thread makes it and when.
  [[nodiscard]] std::vector<std::uint8_t> decide_all() const {
    const std::size_t n = organs_.size();
    // For each organ, the later organs it is an earlier neighbour of (CSR by place).
    std::vector<std::uint32_t> at(n + 1, 0), later;
    for (std::size_t q = 0; q < n; ++q)
      for (const std::uint32_t p : neighbours_.of(q)) ++at[p + 1];
    for (std::size_t p = 0; p < n; ++p) at[p + 1] += at[p];
    later.resize(at[n]);
    std::vector<std::uint32_t> next(at.begin(), at.end() - 1);
    for (std::uint32_t q = 0; q < n; ++q)
      for (const std::uint32_t p : neighbours_.of(q)) later[next[p]++] = q;
    std::vector<std::atomic<std::uint32_t>> waiting(n);  // earlier neighbours not yet decided
    std::vector<std::uint32_t> ready;
    for (std::uint32_t p = 0; p < n; ++p) {
      waiting[p].store(static_cast<std::uint32_t>(neighbours_.of(p).size()), std::memory_order_relaxed);
      if (neighbours_.of(p).empty()) ready.push_back(p);
    }
    std::vector<std::uint8_t> decision(n, kDropped);
    tbb::enumerable_thread_specific<ShapeTests> tests([n] { return ShapeTests(n); });
    tbb::parallel_for_each(ready.begin(), ready.end(), [&](std::uint32_t p, tbb::feeder<std::uint32_t>& feeder) {
      decision[p] = decide(p, decision, tests.local());
      // Release: the organ this makes ready reads the decision.
      for (std::uint32_t e = at[p]; e < at[p + 1]; ++e)
        if (waiting[later[e]].fetch_sub(1, std::memory_order_acq_rel) == 1) feeder.add(later[e]);
    });
    return decision;
  }

  // What the organ at place p takes: its first candidate that no branch but its own stem blocks and
  // that meets no candidate its earlier neighbours took.
  std::uint8_t decide(std::uint32_t p, const std::vector<std::uint8_t>& decision, ShapeTests& tests) const {
    const std::uint8_t variants = candidates_.count(organs_[p].kind);
    for (std::uint8_t v = 0; v < variants; ++v) {
      const Organ o = as(p, v);
      const Probe box = probe(o);
      tests.begin(o, shapes_.of(o));
      if (branches_.block(box, o.node, tests)) continue;
      bool meets = false;
      for (const std::uint32_t q : neighbours_.of(p)) {
        if (decision[q] == kDropped) continue;
        const Organ taken = as(q, decision[q]);
        if (!boxes_meet(box, probe(taken)) || !tests.meets(q, taken, shapes_.of(taken))) continue;
        meets = true;
        break;
      }
      if (!meets) return v;
    }
    return kDropped;
  }

  Plant& plant_;
  const Branches branches_;
  const Candidates candidates_;
  const OrganShapes shapes_;
  const Neighbours neighbours_;
  std::vector<Organ> organs_;  // by place in the neighbours' tree: organs near in space, near in memory
};

}  // namespace

PlacementCounts place_organs(Plant& plant, const OrganOptions& opt, const OrganShape* custom_leaf) {
  if (opt.placement != "avoid") {
    PlacementCounts c;
    c.placed = plant.organs.size();
    for (const Organ& o : plant.organs) ++c.by_kind[static_cast<std::size_t>(o.kind)].placed;
    return c;
  }
  return Placement(plant, opt, custom_leaf).run();
}

}  // namespace growbench
