// Whether a grown plant is one its numbers may stand for. General invariants every plant must keep, each
// with its threshold here and its reason in docs/metrics.md ("Validity"), plus the algorithm's own word
// (GrowthAlgorithm::own_verdict): a plant that fails any is degenerate, and a scene the algorithm says it
// cannot grow on makes the trial not applicable. Reports leave both out of comparisons across cells.
#pragma once

#include <nlohmann/json.hpp>

#include "algorithms/algorithm.hpp"
#include "harness/record/record.hpp"
#include "scenes/scene.hpp"

namespace growbench {

struct ValidityOptions {
  // Stunted: the mean segment is shorter than this fraction of the scene's bounding-box diagonal.
  double min_mean_segment = 1e-4;
  // Flat: the nodes' vertical extent is below this fraction of their horizontal extent.
  double flat_ratio = 0.02;
  // Seeds: fewer than this fraction of the plant's roots grew a branch.
  double min_roots_grown = 0.5;
  // Inside: more than this fraction of the branches' interior samples lie inside solids (metric
  // penetration_samples).
  double max_inside = 0.5;
  // Folded: more than this fraction of the segments cross another (metric self_intersection_fraction).
  // Dense real plants touch their neighbours often, so only nearly all is a fold.
  double max_self_intersecting = 0.98;
};

// The verdict on `plant`, grown on `scene`. `metrics` (compute_metrics) may be null, with metrics off: the
// checks that need them are then skipped.
Verdict judge_plant(const Plant& plant, const Scene& scene, const nlohmann::json* metrics, const OwnVerdict& own,
                    const ValidityOptions& options = {});

}  // namespace growbench
