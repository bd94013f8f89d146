// Quality metrics, computed the same way for every algorithm from the Plant and the scene. Each one's
// definition, error bound and meaning: docs/metrics.md.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "algorithms/organ_shapes.hpp"
#include "algorithms/plant.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {

struct MetricOptions {
  float coverage_distance = 0.05f;  // a surface sample within this of a branch segment is covered (m)
  int coverage_samples = 4000;      // area-weighted samples on the climbable surfaces
  std::uint64_t coverage_seed = 0xC0FE;
  float attach_distance = 0.02f;  // a node within this of a surface is attached (m)
  int segment_samples = 3;        // interior points per segment tested for penetration
  float light_bias = 1e-3f;       // a leaf's light ray leaves from this far above its centre (m)
  // From this many segments, the self-intersection search reads them in space order (metrics.cpp,
  // in_space_order): the same figures, faster on plants too large for the cache.
  std::size_t space_order_from = std::size_t{1} << 17;
  // The trial's custom organ (MesherOptions::leaf), or null. Leaf overlap and self-shadowing take each
  // organ's shape as the mesher does (organ_shapes), so they judge the organs as they are exported.
  std::shared_ptr<const OrganShape> custom_leaf;
};

// The verdict on every item behind the figures, for tests that check them one by one.
struct MetricDetails {
  std::vector<std::uint8_t> covered;          // per coverage sample
  std::vector<float> node_distance;           // per node: to the nearest surface (m)
  std::vector<std::uint8_t> node_inside;      // per node
  std::vector<std::uint32_t> segments;        // per segment: its child node (the parent is the node's)
  std::vector<std::uint8_t> sample_inside;    // per segment sample: segment k's j-th at k * segment_samples + j
  std::vector<std::uint8_t> segment_crossed;  // per segment: in a self-intersecting pair
  std::vector<std::uint32_t> leaves;          // per leaf: its organ index
  std::vector<std::uint8_t> leaf_overlaps;    // per leaf: its blade meets another leaf's
  std::vector<std::uint8_t> leaf_lit_scene;   // per leaf: the scene leaves its light ray free
  std::vector<std::uint8_t> leaf_lit;         // per leaf: the scene and the plant leave it free
};

// Keys (all present, numbers):
//  nodes, segments, leaves, flowers, polygons, total_length_m, max_branch_order, max_depth (segments
//  from a root to the farthest node), bbox_min, bbox_max ([x,y,z]), coverage (fraction of surface
//  samples within coverage_distance of a segment), adhesion_mean_m, adhesion_median_m, adhesion_p90_m
//  (node distance to the nearest surface), attached_fraction, penetration_nodes (fraction of nodes
//  inside a solid, by SceneQuery::inside), penetration_samples (fraction of segment sample points
//  inside), self_intersections (pairs of segments closer than the sum of their radii, not counting
//  neighbours: segments whose child nodes' {node, parent, grandparent} sets meet),
//  self_intersection_fraction (of segments in such a pair), leaf_overlap (fraction of leaves whose blade
//  crosses another leaf's), leaf_light_exposure (fraction of leaves whose centre has a free ray to the
//  light past the scene and the plant's own branches, leaves and flowers), leaf_light_exposure_scene
//  (the same with only the scene occluding).
nlohmann::json compute_metrics(const Plant& plant, const SceneQuery& query, const MetricOptions& options = {},
                               MetricDetails* details = nullptr);

// A leaf's centre (half a blade from its stem) and the normal of its upper side: where its light ray
// leaves from, offset along the normal by MetricOptions::light_bias.
glm::vec3 leaf_centre(const Organ& leaf);
glm::vec3 leaf_normal(const Organ& leaf);
bool is_leaf(const Organ& organ);

}  // namespace growbench
