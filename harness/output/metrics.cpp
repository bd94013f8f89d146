#include "harness/output/metrics.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <glm/gtc/quaternion.hpp>
#include <tbb/parallel_for.h>

#include "core/kdtree.hpp"
#include "harness/output/mesher.hpp"
#include "scenes/geometry.hpp"

namespace growbench {
namespace {

using PointsAdaptor = Vec3Cloud;
using Tree = Vec3Tree;

float point_segment_distance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float t = len2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return glm::length(p - (a + t * ab));
}

// A fraction of `of`, or null (not applicable) when there is nothing to take a fraction of.
nlohmann::json ratio(std::size_t count, std::size_t of) {
  return of == 0 ? nlohmann::json() : nlohmann::json(static_cast<double>(count) / static_cast<double>(of));
}

double quantile(std::vector<float> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const auto hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

}  // namespace

bool is_leaf(const Organ& o) {
  return o.kind == OrganKind::Leaf || o.kind == OrganKind::YoungLeaf;
}
glm::vec3 leaf_centre(const Organ& leaf) {
  return organ_point(leaf, {0.0f, 0.0f, 0.5f});
}
glm::vec3 leaf_normal(const Organ& leaf) {
  return glm::mat3_cast(leaf.orientation)[1];
}

namespace {

// One pass of compute_metrics, a method per metric family; what several families share (the segments,
// their midpoints' kd-tree, the leaves) is built once, and what `details` reports is kept as members.
class MetricsPass {
 public:
  MetricsPass(const Plant& plant, const SceneQuery& query, const MetricOptions& o)
      : plant(plant), nodes(plant.nodes), query(query), o(o) {
    // Segments: node i (with a parent) and its parent.
    for (std::uint32_t i = 0; i < nodes.size(); ++i)
      if (nodes[i].parent != kNoParent) seg.push_back(i);
    if (seg.size() >= o.space_order_from) in_space_order();
  }

  nlohmann::json run(MetricDetails* details) {
    counts();
    index_segments();
    coverage();
    adhesion_and_penetration();
    self_intersection();
    leaf_metrics();
    if (details) keep(*details);
    return std::move(m);
  }

 private:
  glm::vec3 a_of(std::uint32_t s) const { return nodes[static_cast<std::size_t>(nodes[s].parent)].position; }

  void counts() {
    std::size_t leaves = 0, flowers = 0;
    for (const auto& org : plant.organs) {
      if (is_leaf(org))
        ++leaves;
      else
        ++flowers;
    }
    m["nodes"] = nodes.size();
    m["segments"] = seg.size();
    m["leaves"] = leaves;
    m["flowers"] = flowers;
    m["polygons"] = plant.polygons.size();
    m["total_length_m"] = plant.total_length();

    int max_order = 0, max_depth = 0;
    std::vector<int> depth(nodes.size(), 0);
    Aabb box;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      if (nodes[i].parent != kNoParent) depth[i] = depth[static_cast<std::size_t>(nodes[i].parent)] + 1;
      max_depth = std::max(max_depth, depth[i]);
      max_order = std::max(max_order, static_cast<int>(nodes[i].order));
      box.extend(nodes[i].position);
    }
    m["max_branch_order"] = max_order;
    m["max_depth"] = max_depth;
    const glm::vec3 lo = box.empty() ? glm::vec3(0.0f) : box.min, hi = box.empty() ? glm::vec3(0.0f) : box.max;
    m["bbox_min"] = {lo.x, lo.y, lo.z};
    m["bbox_max"] = {hi.x, hi.y, hi.z};
  }

  // A large plant has its segments put along a Morton curve of their midpoints, and the pair test
  // reads each segment's ends from a copy in that order: its nodes are stored in the order they grew, where
  // neighbours in space lie far apart, and reading them there was most of the self-intersection search on
  // plants of millions of nodes (below MetricOptions::space_order_from segments the arrays fit in cache and
  // the copies would cost more than they save). Every figure is a count over all segments and ties are
  // broken by node index, so no figure depends on the order.
  void in_space_order() {
    if (seg.size() < 2) return;
    Aabb box;
    for (const std::uint32_t i : seg) box.extend(nodes[i].position);
    const glm::vec3 scale = 1023.0f / glm::max(box.size(), glm::vec3(1e-30f));
    auto spread = [](std::uint32_t v) {  // 10 bits to every third of 30
      v = (v | (v << 16)) & 0x030000FFu;
      v = (v | (v << 8)) & 0x0300F00Fu;
      v = (v | (v << 4)) & 0x030C30C3u;
      return (v | (v << 2)) & 0x09249249u;
    };
    std::vector<std::uint64_t> keyed(seg.size());
    for (std::size_t k = 0; k < seg.size(); ++k) {
      const glm::vec3 c = glm::clamp((0.5f * (a_of(seg[k]) + nodes[seg[k]].position) - box.min) * scale, 0.0f, 1023.0f);
      const std::uint32_t code = spread(static_cast<std::uint32_t>(c.x)) |
                                 (spread(static_cast<std::uint32_t>(c.y)) << 1) |
                                 (spread(static_cast<std::uint32_t>(c.z)) << 2);
      keyed[k] = (static_cast<std::uint64_t>(code) << 32) | seg[k];  // ties in node order
    }
    std::sort(keyed.begin(), keyed.end());
    for (std::size_t k = 0; k < seg.size(); ++k) seg[k] = static_cast<std::uint32_t>(keyed[k]);
  }

  void index_segments() {
    // Segment midpoints in a kd-tree: exact point-segment and segment-segment distances near them.
    // A segment's reach: its half length plus its radius.
    mid.resize(seg.size());
    reach.resize(seg.size());
    for (std::size_t k = 0; k < seg.size(); ++k) {
      const glm::vec3 a = a_of(seg[k]), b = nodes[seg[k]].position;
      const float half = 0.5f * glm::length(b - a);
      mid[k] = 0.5f * (a + b);
      max_half = std::max(max_half, half);
      reach[k] = half + nodes[seg[k]].radius;
    }
    // Searches visit candidates in place (kd_visit_within): a result list per query would allocate for every
    // node, and this phase's allocation count must repeat run to run.
    if (!seg.empty()) tree = std::make_unique<Tree>(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  }

  void coverage() {
    // Coverage.
    // Of the climbable surfaces only: a scene with none (the ground alone) has nothing to cover.
    const int ns = query.scene().has_climbable() && query.sampled_area() > 0.0 ? o.coverage_samples : 0;
    covered.assign(static_cast<std::size_t>(ns), 0);
    if (tree) {
      tbb::parallel_for(0, ns, [&](int i) {
        const glm::vec3 p = query.sample_surface(o.coverage_seed, static_cast<std::uint64_t>(i)).position;
        kd_visit_within(*tree, p, o.coverage_distance + max_half, [&](std::uint32_t k, float) {
          if (point_segment_distance(p, a_of(seg[k]), nodes[seg[k]].position) > o.coverage_distance) return true;
          covered[static_cast<std::size_t>(i)] = 1;
          return false;
        });
      });
    }
    std::size_t cov = 0;
    for (const auto c : covered) cov += c;
    m["coverage"] = ratio(cov, static_cast<std::size_t>(ns));  // n/a in a scene with nothing to cover
  }

  void adhesion_and_penetration() {
    // Adhesion and penetration of nodes.
    dist.resize(nodes.size());
    inside.resize(nodes.size());
    tbb::parallel_for(std::size_t{0}, nodes.size(), [&](std::size_t i) {
      dist[i] = query.closest_point(nodes[i].position).distance;
      inside[i] = query.inside(nodes[i].position) ? 1 : 0;
    });
    std::size_t attached = 0, inside_nodes = 0;
    double sum = 0.0;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      attached += dist[i] <= o.attach_distance ? 1 : 0;
      inside_nodes += inside[i];
      sum += dist[i];
    }
    const double n = std::max<double>(1.0, static_cast<double>(nodes.size()));
    m["adhesion_mean_m"] = nodes.empty() ? nlohmann::json() : nlohmann::json(sum / n);
    m["adhesion_median_m"] = nodes.empty() ? nlohmann::json() : nlohmann::json(quantile(dist, 0.5));
    m["adhesion_p90_m"] = nodes.empty() ? nlohmann::json() : nlohmann::json(quantile(dist, 0.9));
    m["attached_fraction"] = ratio(attached, nodes.size());
    m["penetration_nodes"] = ratio(inside_nodes, nodes.size());
    const auto ss = static_cast<std::size_t>(std::max(0, o.segment_samples));
    sample_inside.assign(seg.size() * ss, 0);
    tbb::parallel_for(std::size_t{0}, seg.size(), [&](std::size_t k) {
      const glm::vec3 a = a_of(seg[k]), b = nodes[seg[k]].position;
      for (std::size_t j = 0; j < ss; ++j) {
        const float t = static_cast<float>(j + 1) / static_cast<float>(ss + 1);
        sample_inside[k * ss + j] = query.inside(glm::mix(a, b, t)) ? 1 : 0;
      }
    });
    std::size_t inside_samples = 0;
    for (const auto c : sample_inside) inside_samples += c;
    m["penetration_samples"] = ratio(inside_samples, sample_inside.size());
  }

  void self_intersection() {
    // Self-intersection: pairs (k < l) closer than r_k + r_l that are not neighbours in the tree.
    // Neighbours: the {node, parent, grandparent} sets of the two segments' child nodes meet (they share a
    // node, or sit within two segments of each other along the tree, where thick junctions always touch).
    auto up = [&](std::int32_t v) { return v == kNoParent ? kNoParent : nodes[static_cast<std::size_t>(v)].parent; };
    auto neighbours = [&](std::uint32_t x, std::uint32_t y) {
      const std::int32_t X[3] = {static_cast<std::int32_t>(x), up(static_cast<std::int32_t>(x)),
                                 up(up(static_cast<std::int32_t>(x)))};
      const std::int32_t Y[3] = {static_cast<std::int32_t>(y), up(static_cast<std::int32_t>(y)),
                                 up(up(static_cast<std::int32_t>(y)))};
      for (const auto a : X)
        for (const auto b : Y)
          if (a != kNoParent && a == b) return true;
      return false;
    };
    // Each pair is judged once, from the segment with the larger reach (half length + radius; ties go to
    // the lower node index): a pair can only meet within the sum of the two reaches, at most twice the larger
    // one. Searching with the plant's largest radius and half length instead made every thin segment near
    // a thick stem visit hundreds of candidates.
    auto judged_from = [&](std::size_t k, std::size_t l) {
      return reach[l] < reach[k] || (reach[l] == reach[k] && seg[l] > seg[k]);
    };
    std::vector<std::uint32_t> pairs_of(seg.size(), 0);
    involved = std::vector<std::atomic<std::uint8_t>>(seg.size());  // zero-initialised; set from either side
    auto from_nodes = [&](std::size_t k) { return Ends{a_of(seg[k]), nodes[seg[k]].position, nodes[seg[k]].radius}; };
    if (seg.size() < o.space_order_from) {
      count_crossings(from_nodes, judged_from, neighbours, pairs_of);
    } else {  // see in_space_order
      std::vector<Ends> ends(seg.size());
      tbb::parallel_for(std::size_t{0}, seg.size(), [&](std::size_t k) { ends[k] = from_nodes(k); });
      count_crossings([&](std::size_t k) -> const Ends& { return ends[k]; }, judged_from, neighbours, pairs_of);
    }
    std::size_t pairs = 0, inv = 0;
    for (std::size_t k = 0; k < seg.size(); ++k) {
      pairs += pairs_of[k];
      inv += involved[k].load(std::memory_order_relaxed);
    }
    m["self_intersections"] = pairs;
    m["self_intersection_fraction"] = ratio(inv, seg.size());
  }

  struct Ends {
    glm::vec3 a, b;
    float radius;
  };

  // Every pair of segments that cross, judged from one side: counted in pairs_of, both marked in involved.
  template <class EndsOf, class JudgedFrom, class Neighbours>
  void count_crossings(const EndsOf& ends, const JudgedFrom& judged_from, const Neighbours& neighbours,
                       std::vector<std::uint32_t>& pairs_of) {
    if (!tree) return;
    tbb::parallel_for(std::size_t{0}, seg.size(), [&](std::size_t k) {
      const Ends ek = ends(k);
      kd_visit_within(*tree, mid[k], 2.0f * reach[k] * (1.0f + 1e-4f), [&](std::uint32_t l, float d2) {
        // Cheapest first, as in a dense plant most candidates fail: two segments whose midpoints are farther
        // apart than the sum of their reaches cannot meet; the tree check reads nodes far apart in memory,
        // so it comes last, for the pairs that do meet.
        const float reach_sum = (reach[k] + reach[l]) * (1.0f + 1e-4f);
        if (!judged_from(k, l) || d2 > reach_sum * reach_sum) return true;
        const Ends& el = ends(l);
        // Always the lower node index first, so a pair's verdict does not depend on the side judging it.
        const float d = seg[k] < seg[l] ? geom::segment_distance(ek.a, ek.b, el.a, el.b)
                                        : geom::segment_distance(el.a, el.b, ek.a, ek.b);
        if (d < ek.radius + el.radius && !neighbours(seg[k], seg[l])) {
          involved[k].store(1, std::memory_order_relaxed);
          involved[l].store(1, std::memory_order_relaxed);
          ++pairs_of[k];
        }
        return true;
      });
    });
  }

  void leaf_metrics() {
    // Leaves: their blades as exported (the organ shape placed by organ_point), and light.
    const OrganShapes shapes(plant, o.custom_leaf.get());
    auto organ_triangle = [&](const Organ& org, const glm::uvec3& t, glm::vec3(&v)[3]) {
      const auto& vertices = shapes.of(org).mesh.vertices;
      for (int k = 0; k < 3; ++k) v[k] = organ_point(org, vertices[t[k]]);
    };
    for (std::uint32_t i = 0; i < plant.organs.size(); ++i)
      if (is_leaf(plant.organs[i])) leaf.push_back(i);
    // Each leaf's bounding sphere (around its box's centre) finds the leaves its blade can meet.
    std::vector<glm::vec3> bcentre(leaf.size());
    std::vector<float> bradius(leaf.size(), 0.0f);
    std::vector<Aabb> lbox(leaf.size());
    for (std::size_t i = 0; i < leaf.size(); ++i) {
      for (const auto& v : shapes.of(plant.organs[leaf[i]]).mesh.vertices)
        lbox[i].extend(organ_point(plant.organs[leaf[i]], v));
      // Padded by the overlap test's tolerance, so blades coplanar within it are not kept apart here.
      const glm::vec3 far = glm::max(glm::abs(lbox[i].min), glm::abs(lbox[i].max));
      const float reach = std::max({far.x, far.y, far.z});
      const float pad = 1e-6f * glm::length(lbox[i].size()) + 8.0f * std::numeric_limits<float>::epsilon() * reach;
      lbox[i].min -= glm::vec3(2.0f * pad);
      lbox[i].max += glm::vec3(2.0f * pad);
      bcentre[i] = lbox[i].center();
      bradius[i] = 0.5f * glm::length(lbox[i].size());
    }
    auto blades_meet = [&](std::size_t i, std::size_t j) {
      const Aabb &a = lbox[i], &b = lbox[j];
      if (glm::any(glm::lessThan(a.max, b.min)) || glm::any(glm::lessThan(b.max, a.min))) return false;
      glm::vec3 ta[3], tb[3];
      const Organ &oi = plant.organs[leaf[i]], &oj = plant.organs[leaf[j]];
      for (const auto& t : shapes.of(oi).mesh.triangles) {
        organ_triangle(oi, t, ta);
        for (const auto& u : shapes.of(oj).mesh.triangles) {
          organ_triangle(oj, u, tb);
          if (geom::triangles_overlap(ta, tb)) return true;
        }
      }
      return false;
    };
    overlap.assign(leaf.size(), 0);
    lit_scene.assign(leaf.size(), 0);
    lit.assign(leaf.size(), 0);
    if (!leaf.empty()) {
      PointsAdaptor la{&bcentre};
      Tree leaf_tree(3, la, nanoflann::KDTreeSingleIndexAdaptorParams(16));
      const float rmax = *std::max_element(bradius.begin(), bradius.end());
      // The plant as an occluder: branches as the mesher's tubes (capsules between node radii, raised to
      // its minimum), every organ's triangles owned by the organ, and polygons.
      std::vector<Occluder::Capsule> capsules;
      capsules.reserve(seg.size());
      for (const auto s : seg)
        capsules.push_back({a_of(s), nodes[s].position,
                            std::max(nodes[static_cast<std::size_t>(nodes[s].parent)].radius, 1e-4f),
                            std::max(nodes[s].radius, 1e-4f)});
      std::vector<Occluder::Triangle> tris;
      std::size_t organ_triangles = 0;
      for (const auto& org : plant.organs) organ_triangles += shapes.of(org).mesh.triangles.size();
      tris.reserve(organ_triangles);
      for (std::uint32_t i = 0; i < plant.organs.size(); ++i)
        for (const auto& t : shapes.of(plant.organs[i]).mesh.triangles) {
          Occluder::Triangle ot;
          organ_triangle(plant.organs[i], t, ot.v);
          ot.owner = i;
          tris.push_back(ot);
        }
      for (const auto& poly : plant.polygons)
        for (std::size_t k = 1; k + 1 < poly.vertices.size(); ++k)
          tris.push_back({{poly.vertices[0], poly.vertices[k], poly.vertices[k + 1]}});
      const auto occluder = query.occluder(std::move(capsules), std::move(tris));
      tbb::parallel_for(std::size_t{0}, leaf.size(), [&](std::size_t i) {
        // Stops at the first leaf it meets: dense foliage (the wall's ivy has hundreds of leaves within
        // reach of each) would otherwise test every candidate only to learn one thing.
        kd_visit_within(leaf_tree, bcentre[i], bradius[i] + rmax, [&](std::uint32_t j, float d2) {
          if (j == i || std::sqrt(d2) > bradius[i] + bradius[j] || !blades_meet(i, j)) return true;
          overlap[i] = 1;
          return false;
        });
        const Organ& org = plant.organs[leaf[i]];
        const glm::vec3 from = leaf_centre(org) + o.light_bias * leaf_normal(org);
        lit_scene[i] = query.light_visible(from) ? 1 : 0;
        const Light& light = query.scene().light;
        lit[i] = lit_scene[i] && !occluder->occluded(from, light.towards(from), light.distance(from), leaf[i]) ? 1 : 0;
      });
    }
    std::size_t ov = 0, li = 0, ls = 0;
    for (std::size_t i = 0; i < leaf.size(); ++i) {
      ov += overlap[i];
      li += lit[i];
      ls += lit_scene[i];
    }
    m["leaf_overlap"] = ratio(ov, leaf.size());  // n/a without leaves: no overlap is not the best overlap
    m["leaf_light_exposure"] = ratio(li, leaf.size());
    m["leaf_light_exposure_scene"] = ratio(ls, leaf.size());
  }

  void keep(MetricDetails& d) {
    d.covered = std::move(covered);
    d.node_distance = std::move(dist);
    d.node_inside = std::move(inside);
    d.segments = std::move(seg);
    d.sample_inside = std::move(sample_inside);
    d.segment_crossed.resize(involved.size());
    for (std::size_t k = 0; k < involved.size(); ++k)
      d.segment_crossed[k] = involved[k].load(std::memory_order_relaxed);
    d.leaves = std::move(leaf);
    d.leaf_overlaps = std::move(overlap);
    d.leaf_lit_scene = std::move(lit_scene);
    d.leaf_lit = std::move(lit);
  }

  const Plant& plant;
  const std::vector<PlantNode>& nodes;
  const SceneQuery& query;
  const MetricOptions& o;
  nlohmann::json m;
  std::vector<std::uint32_t> seg;  // node index of each segment's child end
  std::vector<glm::vec3> mid;      // segment midpoints
  std::vector<float> reach;        // half length plus radius
  float max_half = 0.0f;
  PointsAdaptor adaptor{&mid};
  std::unique_ptr<Tree> tree;  // the midpoints; null without segments
  std::vector<std::uint8_t> covered, inside, sample_inside;
  std::vector<float> dist;
  std::vector<std::atomic<std::uint8_t>> involved;
  std::vector<std::uint32_t> leaf;  // organ index of each leaf
  std::vector<std::uint8_t> overlap, lit_scene, lit;
};

}  // namespace

nlohmann::json compute_metrics(const Plant& plant, const SceneQuery& query, const MetricOptions& o,
                               MetricDetails* details) {
  return MetricsPass(plant, query, o).run(details);
}

}  // namespace growbench
