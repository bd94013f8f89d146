// Quality metrics, computed the same way for every algorithm from the Plant and the scene.
#pragma once

#include <nlohmann/json.hpp>

#include "algorithms/plant.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {

struct MetricOptions {
  float coverage_distance = 0.05f;  // a surface sample within this of a branch segment is covered (m)
  int coverage_samples = 4000;      // area-weighted samples on the climbable surfaces
  std::uint64_t coverage_seed = 0xC0FE;
  float attach_distance = 0.02f;    // a node within this of a surface is attached (m)
  int segment_samples = 3;          // interior points per segment tested for penetration
};

// Keys (all present, numbers):
//  nodes, segments, leaves, flowers, polygons, total_length_m, max_branch_order, max_depth (segments
//  from a root to the farthest node), bbox_min, bbox_max ([x,y,z]), coverage (fraction of surface
//  samples within coverage_distance of a segment), adhesion_mean_m, adhesion_median_m, adhesion_p90_m
//  (node distance to the nearest surface), attached_fraction, penetration_nodes (fraction of nodes
//  inside a solid), penetration_samples (fraction of segment sample points inside), self_intersections
//  (pairs of segments closer than the sum of their radii, not counting neighbours: segments whose child
//  nodes' {node, parent, grandparent} sets meet), self_intersection_fraction (of segments in such a pair), leaf_overlap
//  (fraction of leaves whose bounding disc meets another's), leaf_light_exposure (fraction of leaves
//  whose centre has an unoccluded ray to the light; the scene occludes, the plant does not).
nlohmann::json compute_metrics(const Plant& plant, const SceneQuery& query, const MetricOptions& options = {});

// Distance between segments [p0,p1] and [q0,q1] (Ericson 5.1.9).
float segment_distance(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& q0, const glm::vec3& q1);

}  // namespace growbench
