#include "harness/metrics.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <glm/gtc/quaternion.hpp>
#include <tbb/parallel_for.h>

#include "core/kdtree.hpp"

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

double quantile(std::vector<float> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const auto hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

}  // namespace

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

nlohmann::json compute_metrics(const Plant& plant, const SceneQuery& query, const MetricOptions& o) {
  const auto& nodes = plant.nodes;
  nlohmann::json m;
  // Segments: node i (with a parent) and its parent.
  std::vector<std::uint32_t> seg;
  for (std::uint32_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].parent != kNoParent) seg.push_back(i);
  auto a_of = [&](std::uint32_t s) { return nodes[static_cast<std::size_t>(nodes[s].parent)].position; };

  std::size_t leaves = 0, flowers = 0;
  for (const auto& org : plant.organs) {
    if (org.kind == OrganKind::Leaf || org.kind == OrganKind::YoungLeaf) ++leaves;
    else ++flowers;
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

  // Segment midpoints in a kd-tree: exact point-segment and segment-segment distances near them.
  // A segment's reach: its half length plus its radius.
  std::vector<glm::vec3> mid(seg.size());
  std::vector<float> reach(seg.size());
  float max_half = 0.0f;
  for (std::size_t k = 0; k < seg.size(); ++k) {
    const glm::vec3 a = a_of(seg[k]), b = nodes[seg[k]].position;
    const float half = 0.5f * glm::length(b - a);
    mid[k] = 0.5f * (a + b);
    max_half = std::max(max_half, half);
    reach[k] = half + nodes[seg[k]].radius;
  }
  // Searches visit candidates in place (kd_visit_within): a result list per query cost ~8.5M allocations
  // (9 GB) on the wall's 416k-node ivy, and this phase's allocation count must repeat run to run.
  PointsAdaptor adaptor{&mid};
  std::unique_ptr<Tree> tree;
  if (!seg.empty()) tree = std::make_unique<Tree>(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));

  // Coverage.
  const int ns = query.sampled_area() > 0.0 ? o.coverage_samples : 0;
  std::vector<std::uint8_t> covered(static_cast<std::size_t>(ns), 0);
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
  m["coverage"] = ns > 0 ? static_cast<double>(cov) / ns : 0.0;

  // Adhesion and penetration of nodes.
  std::vector<float> dist(nodes.size());
  std::vector<std::uint8_t> inside(nodes.size());
  tbb::parallel_for(std::size_t{0}, nodes.size(), [&](std::size_t i) {
    dist[i] = query.closest_point(nodes[i].position).distance;
    inside[i] = query.has_sdf() && query.signed_distance(nodes[i].position) < 0.0f ? 1 : 0;
  });
  std::size_t attached = 0, inside_nodes = 0;
  double sum = 0.0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    attached += dist[i] <= o.attach_distance ? 1 : 0;
    inside_nodes += inside[i];
    sum += dist[i];
  }
  const double n = std::max<double>(1.0, static_cast<double>(nodes.size()));
  m["adhesion_mean_m"] = nodes.empty() ? 0.0 : sum / n;
  m["adhesion_median_m"] = quantile(dist, 0.5);
  m["adhesion_p90_m"] = quantile(dist, 0.9);
  m["attached_fraction"] = nodes.empty() ? 0.0 : static_cast<double>(attached) / n;
  m["penetration_nodes"] = nodes.empty() ? 0.0 : static_cast<double>(inside_nodes) / n;
  std::vector<std::uint16_t> seg_inside(seg.size(), 0);
  if (query.has_sdf()) {
    tbb::parallel_for(std::size_t{0}, seg.size(), [&](std::size_t k) {
      const glm::vec3 a = a_of(seg[k]), b = nodes[seg[k]].position;
      for (int j = 1; j <= o.segment_samples; ++j) {
        const float t = static_cast<float>(j) / static_cast<float>(o.segment_samples + 1);
        seg_inside[k] = static_cast<std::uint16_t>(seg_inside[k] + (query.signed_distance(glm::mix(a, b, t)) < 0.0f ? 1 : 0));
      }
    });
  }
  std::size_t inside_samples = 0;
  for (const auto c : seg_inside) inside_samples += c;
  const double total_samples = static_cast<double>(seg.size()) * o.segment_samples;
  m["penetration_samples"] = total_samples > 0 ? static_cast<double>(inside_samples) / total_samples : 0.0;

  // Self-intersection: pairs (k < l) closer than r_k + r_l that are not neighbours in the tree.
  // Neighbours: the {node, parent, grandparent} sets of the two segments' child nodes meet (they share a
  // node, or sit within two segments of each other along the tree, where thick junctions always touch).
  auto up = [&](std::int32_t v) { return v == kNoParent ? kNoParent : nodes[static_cast<std::size_t>(v)].parent; };
  auto neighbours = [&](std::uint32_t x, std::uint32_t y) {
    const std::int32_t X[3] = {static_cast<std::int32_t>(x), up(static_cast<std::int32_t>(x)), up(up(static_cast<std::int32_t>(x)))};
    const std::int32_t Y[3] = {static_cast<std::int32_t>(y), up(static_cast<std::int32_t>(y)), up(up(static_cast<std::int32_t>(y)))};
    for (const auto a : X)
      for (const auto b : Y)
        if (a != kNoParent && a == b) return true;
    return false;
  };
  // Each pair is judged once, from the segment with the larger reach (half length + radius; ties go to
  // the lower index): a pair can only meet within the sum of the two reaches, at most twice the larger
  // one. Searching with the plant's largest radius and half length instead made every thin segment near
  // a thick stem visit hundreds of candidates.
  auto judged_from = [&](std::size_t k, std::size_t l) { return reach[l] < reach[k] || (reach[l] == reach[k] && l > k); };
  std::vector<std::uint32_t> pairs_of(seg.size(), 0);
  std::vector<std::atomic<std::uint8_t>> involved(seg.size());  // zero-initialised; set from either side
  if (tree) {
    tbb::parallel_for(std::size_t{0}, seg.size(), [&](std::size_t k) {
      const glm::vec3 a = a_of(seg[k]), b = nodes[seg[k]].position;
      kd_visit_within(*tree, mid[k], 2.0f * reach[k] * (1.0f + 1e-4f), [&](std::uint32_t l, float) {
        if (!judged_from(k, l) || neighbours(seg[k], seg[l])) return true;
        // Always the lower index first, so a pair's verdict does not depend on the side judging it.
        const float d = k < l ? segment_distance(a, b, a_of(seg[l]), nodes[seg[l]].position)
                              : segment_distance(a_of(seg[l]), nodes[seg[l]].position, a, b);
        if (d < nodes[seg[k]].radius + nodes[seg[l]].radius) {
          involved[k].store(1, std::memory_order_relaxed);
          involved[l].store(1, std::memory_order_relaxed);
          ++pairs_of[k];
        }
        return true;
      });
    });
  }
  std::size_t pairs = 0, inv = 0;
  for (std::size_t k = 0; k < seg.size(); ++k) {
    pairs += pairs_of[k];
    inv += involved[k].load(std::memory_order_relaxed);
  }
  m["self_intersections"] = pairs;
  m["self_intersection_fraction"] = seg.empty() ? 0.0 : static_cast<double>(inv) / static_cast<double>(seg.size());

  // Leaves: bounding discs (centre half a blade along +Z, radius half the length), and light.
  std::vector<glm::vec3> centre;
  std::vector<float> radius;
  std::vector<glm::vec3> normal;
  for (const auto& org : plant.organs) {
    if (!(org.kind == OrganKind::Leaf || org.kind == OrganKind::YoungLeaf)) continue;
    const glm::mat3 r = glm::mat3_cast(org.orientation);
    centre.push_back(org.position + 0.5f * org.size * r[2]);
    radius.push_back(0.5f * org.size);
    normal.push_back(r[1]);
  }
  std::vector<std::uint8_t> overlap(centre.size(), 0), lit(centre.size(), 0);
  if (!centre.empty()) {
    PointsAdaptor la{&centre};
    Tree leaf_tree(3, la, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    const float rmax = *std::max_element(radius.begin(), radius.end());
    tbb::parallel_for(std::size_t{0}, centre.size(), [&](std::size_t i) {
      const float r = radius[i] + rmax;
      // Stops at the first overlapping disc: dense foliage (the wall's ivy has ~230 leaf centres within
      // reach of each leaf) would otherwise list every candidate only to learn one thing.
      kd_visit_within(leaf_tree, centre[i], r, [&](std::uint32_t j, float d2) {
        if (j == i || std::sqrt(d2) >= radius[i] + radius[j]) return true;
        overlap[i] = 1;
        return false;
      });
      lit[i] = query.light_visible(centre[i] + 1e-3f * normal[i]) ? 1 : 0;
    });
  }
  std::size_t ov = 0, li = 0;
  for (std::size_t i = 0; i < centre.size(); ++i) {
    ov += overlap[i];
    li += lit[i];
  }
  const double nl = static_cast<double>(centre.size());
  m["leaf_overlap"] = centre.empty() ? 0.0 : static_cast<double>(ov) / nl;
  m["leaf_light_exposure"] = centre.empty() ? 0.0 : static_cast<double>(li) / nl;
  return m;
}

}  // namespace growbench
