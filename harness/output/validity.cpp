#include "harness/output/validity.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace growbench {

namespace {

// A metric's value, when the metrics ran and it applies (a number, not null).
std::optional<double> metric(const nlohmann::json* metrics, const char* key) {
  if (!metrics || !metrics->contains(key) || !(*metrics)[key].is_number()) return std::nullopt;
  return (*metrics)[key].get<double>();
}

std::string percent(double f) {
  return fmt::format("{:.0f}%", 100.0 * f);
}

// The checks on the plant's shape alone.
void check_shape(const Plant& plant, const Scene& scene, const ValidityOptions& o, std::vector<std::string>& out) {
  std::size_t segments = 0, roots = 0;
  std::vector<char> grew(plant.nodes.size(), 0);  // per root: whether it has a child
  Aabb box;
  for (std::size_t i = 0; i < plant.nodes.size(); ++i) {
    const PlantNode& n = plant.nodes[i];
    box.extend(n.position);
    if (n.parent == kNoParent) {
      ++roots;
    } else {
      ++segments;
      if (plant.nodes[static_cast<std::size_t>(n.parent)].parent == kNoParent)
        grew[static_cast<std::size_t>(n.parent)] = 1;
    }
  }
  if (segments == 0 && plant.decals.empty()) {
    out.push_back(
        fmt::format("nothing grew: {} node{} and no branch", plant.nodes.size(), plant.nodes.size() == 1 ? "" : "s"));
    return;
  }
  if (segments == 0) return;
  const double length = plant.total_length();
  const Aabb world = scene.bounds();
  const double diagonal = world.empty() ? 0.0 : static_cast<double>(glm::length(world.max - world.min));
  if (length / static_cast<double>(segments) < o.min_mean_segment * diagonal)
    out.push_back(
        fmt::format("stunted: {} segments of {:.3g} mm on average ({:.3g} m in all), under {:g} of the "
                    "scene's {:.2f} m diagonal",
                    segments, 1e3 * length / static_cast<double>(segments), length, o.min_mean_segment, diagonal));
  const glm::vec3 extent = box.max - box.min;
  const double vertical = extent.y, horizontal = std::hypot(extent.x, extent.z);
  if (horizontal > 0.0 && vertical < o.flat_ratio * horizontal)
    out.push_back(fmt::format("flat: {:.3g} m of branches within {:.3g} cm of height across {:.2f} m", length,
                              100.0 * vertical, horizontal));
  std::size_t grown = 0;
  for (std::size_t i = 0; i < plant.nodes.size(); ++i) grown += grew[i];
  if (roots > 1 && static_cast<double>(grown) < o.min_roots_grown * static_cast<double>(roots))
    out.push_back(fmt::format("seeds: {} of {} grew a branch", grown, roots));
}

// The checks on what the metrics measured against the scene.
void check_measures(const Plant& plant, const Scene& scene, const nlohmann::json* metrics, const ValidityOptions& o,
                    std::vector<std::string>& out) {
  if (const auto inside = metric(metrics, "penetration_samples"); inside && *inside > o.max_inside)
    out.push_back(
        fmt::format("inside: {} of the branches lie inside solids (over {})", percent(*inside), percent(o.max_inside)));
  if (const auto folded = metric(metrics, "self_intersection_fraction"); folded && *folded > o.max_self_intersecting)
    out.push_back(fmt::format("folded: {} of the segments cross another (over {})", percent(*folded),
                              percent(o.max_self_intersecting)));
  const bool climbable = scene.has_climbable();
  for (const auto& d : plant.decals)
    if (d.mesh == kPlanarDecal && !climbable) {
      out.push_back(
          fmt::format("off the scene: {} is drawn on a card, and the scene has no climbable surface to lay "
                      "it on",
                      d.image));
      break;
    }
}

}  // namespace

Verdict judge_plant(const Plant& plant, const Scene& scene, const nlohmann::json* metrics, const OwnVerdict& own,
                    const ValidityOptions& options) {
  Verdict v;
  if (!own.not_applicable.empty()) {
    v.status = "not_applicable";
    v.reasons.push_back(own.not_applicable);
    return v;
  }
  v.reasons = own.degenerate;
  check_shape(plant, scene, options, v.reasons);
  check_measures(plant, scene, metrics, options, v.reasons);
  if (!v.reasons.empty()) v.status = "degenerate";
  return v;
}

}  // namespace growbench
