#include "harness/organs/placement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/quaternion.hpp>
#include <tbb/parallel_for.h>

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

// The organ as its fallback, or false when it has none.
bool fallback_of(Plant& plant, const OrganOptions& opt, Organ& o) {
  switch (o.kind) {
    case OrganKind::Leaf:
    case OrganKind::YoungLeaf:
      if (!(opt.fallback_leaf > 0.0)) return false;
      o.size = static_cast<float>(o.size * opt.fallback_leaf);
      return true;
    case OrganKind::Flower:
    case OrganKind::Bud: {
      const std::string& f = o.kind == OrganKind::Flower ? opt.fallback_flower : opt.fallback_bud;
      if (f == "none") return false;
      o.shape = shape_index(plant, f);
      if (f.rfind("bud", 0) == 0) o.kind = OrganKind::Bud;
      return true;
    }
  }
  return false;
}

double pad_for(const Organ& o) {
  const glm::vec3 p = glm::abs(o.position);
  return 1e-6 * o.size + 4.0 * std::numeric_limits<float>::epsilon() * std::max({p.x, p.y, p.z, o.size});
}

// The distance from the segment (a, b) to the box [-h, h], both in the box's frame: a convex function of
// the segment's parameter, minimised by golden-section search.
double segment_box_distance(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& h) {
  auto dist = [&](double t) {
    const glm::dvec3 p = a + t * (b - a);
    return glm::length(glm::max(glm::abs(p) - h, glm::dvec3(0.0)));
  };
  double lo = 0.0, hi = 1.0;
  constexpr double g = 0.6180339887498949;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = dist(x1), f2 = dist(x2);
  for (int k = 0; k < 60 && hi - lo > 1e-9; ++k) {
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
  return std::min({dist(0.0), dist(1.0), f1, f2});
}

// What one candidate (an organ as grown, or its fallback) needs for the tests.
struct Candidate {
  std::uint32_t organ;
  std::uint8_t variant;  // 0: as grown, 1: fallback
  Organ as;              // the organ as this candidate places it
  const OrganShape* shape;
  OrientedBox box;
  double reach;  // the box's bounding-sphere radius
};

// Whether two candidates' shapes intersect, triangle by triangle, as the leaf_overlap metric tests
// them (geom::triangles_overlap on the triangles organ_point places): organs that only touch, such as
// leaves of one tuft sharing their base, do not. Only triangles whose bounds meet the other organ's are
// paired: disjoint bounds cannot hold a shared point, so this changes no verdict.
bool shapes_meet(const Candidate& a, const Candidate& b) {
  struct Placed {
    std::vector<glm::vec3> v;
    std::vector<Aabb> box;  // per triangle
    Aabb all;
  };
  thread_local Placed pa, pb;
  auto place = [](const Candidate& c, Placed& p) {
    p.v.clear();
    p.box.clear();
    p.all = Aabb{};
    for (const auto& v : c.shape->mesh.vertices) p.v.push_back(organ_point(c.as, v));
    for (const auto& t : c.shape->mesh.triangles) {
      Aabb b;
      for (int k = 0; k < 3; ++k) b.extend(p.v[t[k]]);
      p.box.push_back(b);
      p.all.extend(b.min);
      p.all.extend(b.max);
    }
  };
  auto disjoint = [](const Aabb& x, const Aabb& y) {
    return glm::any(glm::lessThan(x.max, y.min)) || glm::any(glm::lessThan(y.max, x.min));
  };
  place(a, pa);
  place(b, pb);
  if (disjoint(pa.all, pb.all)) return false;
  const auto& ta = a.shape->mesh.triangles;
  const auto& tb = b.shape->mesh.triangles;
  for (std::size_t i = 0; i < ta.size(); ++i) {
    if (disjoint(pa.box[i], pb.all)) continue;
    const glm::vec3 x[3] = {pa.v[ta[i].x], pa.v[ta[i].y], pa.v[ta[i].z]};
    for (std::size_t j = 0; j < tb.size(); ++j) {
      if (disjoint(pa.box[i], pb.box[j])) continue;
      const glm::vec3 y[3] = {pb.v[tb[j].x], pb.v[tb[j].y], pb.v[tb[j].z]};
      if (geom::triangles_overlap(x, y)) return true;
    }
  }
  return false;
}

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
  return segment_box_distance(a, b, box.half) < r;
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

struct Placement {
  Plant& plant;
  const OrganOptions& opt;
  const OrganShapes shapes;
  std::vector<Candidate> cand;       // per organ: its own, then its fallback when it has one
  std::vector<std::uint32_t> first;  // organ -> its first candidate; first[n] = cand.size()

  Placement(Plant& p, const OrganOptions& o, const OrganShape* custom)
      : plant(p), opt(o), shapes(with_fallbacks(p, o), custom) {}

  // The fallback shapes are named in the plant before the shapes are resolved.
  static const Plant& with_fallbacks(Plant& p, const OrganOptions& o) {
    for (const auto* f : {&o.fallback_flower, &o.fallback_bud})
      if (*f != "none") (void)shape_index(p, *f);
    return p;
  }

  void make_candidates() {
    const std::size_t n = plant.organs.size();
    first.resize(n + 1);
    for (std::size_t i = 0; i < n; ++i) {
      first[i] = static_cast<std::uint32_t>(cand.size());
      add(static_cast<std::uint32_t>(i), 0, plant.organs[i]);
      Organ f = plant.organs[i];
      if (fallback_of(plant, opt, f)) add(static_cast<std::uint32_t>(i), 1, f);
    }
    first[n] = static_cast<std::uint32_t>(cand.size());
  }

  void add(std::uint32_t organ, std::uint8_t variant, const Organ& o) {
    const OrientedBox b = organ_box(o, shapes.of(o));
    cand.push_back({organ, variant, o, &shapes.of(o), b, glm::length(b.half)});
  }

  // Each candidate blocked by a branch other than its own stem.
  std::vector<std::uint8_t> blocked_by_branches() const {
    std::vector<std::uint8_t> blocked(cand.size(), 0);
    const auto& nodes = plant.nodes;
    std::vector<glm::vec3> mid;
    std::vector<std::uint32_t> child;
    double reach = 0.0;
    for (std::size_t c = 0; c < nodes.size(); ++c) {
      if (nodes[c].parent == kNoParent) continue;
      const auto& p = nodes[static_cast<std::size_t>(nodes[c].parent)];
      mid.push_back(0.5f * (p.position + nodes[c].position));
      child.push_back(static_cast<std::uint32_t>(c));
      reach = std::max(reach, 0.5 * glm::length(glm::dvec3(p.position - nodes[c].position)) +
                                  std::max({p.radius, nodes[c].radius, 1e-4f}));
    }
    if (mid.empty()) return blocked;
    Vec3Cloud cloud{&mid};
    Vec3Tree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tbb::parallel_for(std::size_t{0}, cand.size(), [&](std::size_t k) {
      const Candidate& c = cand[k];
      const std::int32_t own = plant.organs[c.organ].node;
      kd_visit_within(tree, glm::vec3(c.box.centre), static_cast<float>((c.reach + reach) * (1.0 + 1e-6)),
                      [&](std::uint32_t s, float) {
                        const std::uint32_t ci = child[s];
                        const auto& n = nodes[ci];
                        if (own != kNoParent && (static_cast<std::int32_t>(ci) == own || n.parent == own)) return true;
                        const auto& p = nodes[static_cast<std::size_t>(n.parent)];
                        const double r = std::max({p.radius, n.radius, 1e-4f});
                        if (!capsule_meets_box(glm::dvec3(p.position), glm::dvec3(n.position), r, c.box)) return true;
                        blocked[k] = 1;
                        return false;
                      });
    });
    return blocked;
  }

  // For each candidate, the candidates of earlier organs whose boxes it meets (CSR by candidate).
  void conflicts(std::vector<std::uint32_t>& offset, std::vector<std::uint32_t>& other) const {
    // A tree of the organs (their own boxes' centres); each organ's `spread` reaches the farthest point
    // of any of its candidates' boxes, so two organs whose candidates can meet are within the sum.
    const std::size_t organs = first.size() - 1;
    std::vector<glm::vec3> centres(organs);
    std::vector<double> spread(organs, 0.0);
    double smax = 0.0;
    for (std::size_t i = 0; i < organs; ++i) {
      const std::uint32_t k0 = first[i];
      centres[i] = glm::vec3(cand[k0].box.centre);
      for (std::uint32_t k = k0; k < first[i + 1]; ++k)
        spread[i] = std::max(spread[i], glm::length(cand[k].box.centre - cand[k0].box.centre) + cand[k].reach);
      smax = std::max(smax, spread[i]);
    }
    Vec3Cloud cloud{&centres};
    Vec3Tree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(8));
    // Fixed chunks of organs, joined in order: the lists do not depend on the thread count.
    constexpr std::size_t kChunk = 1024;
    const std::size_t chunks = (organs + kChunk - 1) / kChunk;
    std::vector<std::vector<std::uint32_t>> counts(chunks), lists(chunks);
    tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t ch) {
      std::vector<std::uint32_t> found[2];
      for (std::size_t i = ch * kChunk; i < std::min(organs, (ch + 1) * kChunk); ++i) {
        const std::uint32_t k0 = first[i], k1 = first[i + 1];
        found[0].clear();
        found[1].clear();
        kd_visit_within(tree, centres[i], static_cast<float>((spread[i] + smax) * (1.0 + 1e-6)),
                        [&](std::uint32_t o, float d2) {
                          if (o >= i || std::sqrt(d2) > (spread[i] + spread[o]) * (1.0 + 1e-6)) return true;
                          for (std::uint32_t j = first[o]; j < first[o + 1]; ++j)
                            for (std::uint32_t k = k0; k < k1; ++k)
                              if (boxes_overlap(cand[k].box, cand[j].box) && shapes_meet(cand[k], cand[j]))
                                found[k - k0].push_back(j);
                          return true;
                        });
        for (std::uint32_t k = k0; k < k1; ++k) {
          counts[ch].push_back(static_cast<std::uint32_t>(found[k - k0].size()));
          lists[ch].insert(lists[ch].end(), found[k - k0].begin(), found[k - k0].end());
        }
      }
    });
    offset.assign(1, 0);
    for (std::size_t ch = 0; ch < chunks; ++ch) {
      for (const auto c : counts[ch]) offset.push_back(offset.back() + c);
      other.insert(other.end(), lists[ch].begin(), lists[ch].end());
    }
  }

  PlacementCounts run() {
    make_candidates();
    const std::vector<std::uint8_t> blocked = blocked_by_branches();
    std::vector<std::uint32_t> offset, other;
    conflicts(offset, other);
    // The sweep: an organ takes its first candidate that meets no candidate already taken.
    std::vector<std::uint8_t> taken(cand.size(), 0);
    PlacementCounts counts;
    std::vector<Organ> kept;
    kept.reserve(plant.organs.size());
    for (std::size_t i = 0; i + 1 < first.size(); ++i) {
      bool placed = false;
      for (std::uint32_t k = first[i]; k < first[i + 1] && !placed; ++k) {
        if (blocked[k] || std::any_of(other.begin() + offset[k], other.begin() + offset[k + 1],
                                      [&](std::uint32_t j) { return taken[j] != 0; }))
          continue;
        taken[k] = 1;
        placed = true;
        kept.push_back(cand[k].as);
        ++(cand[k].variant == 1 ? counts.fallen_back : counts.placed);
      }
      if (!placed) ++counts.dropped;
    }
    plant.organs = std::move(kept);
    return counts;
  }
};

}  // namespace

PlacementCounts place_organs(Plant& plant, const OrganOptions& opt, const OrganShape* custom_leaf) {
  if (opt.placement != "avoid") return {plant.organs.size(), 0, 0};
  return Placement(plant, opt, custom_leaf).run();
}

}  // namespace growbench
