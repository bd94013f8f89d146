// What space colonization (spacecol) and its texture-space variant (vines) share of the algorithm:
// where an attraction point may sit with respect to the scene's zones, and the normalised pull that
// leaves a cancelled one at rest. Header-only, so that spacecol still builds alone as a plugin.
#pragma once

#include <glm/glm.hpp>

#include "scenes/host_queries.hpp"
#include "scenes/scene.hpp"

namespace growbench::colonization {

// v / |v|, or `fallback` when v is (nearly) zero: pulls that cancel give no direction.
inline glm::vec3 safe_normalize(const glm::vec3& v, const glm::vec3& fallback = glm::vec3(0.0f)) {
  const float len = glm::length(v);
  return len > 1e-20f ? v / len : fallback;
}

// Whether the scene's zones let an attraction point sit at q: never in an exclude or repel zone, and,
// when the scene has include zones, only inside one of them.
inline bool zones_allow(const Scene& scene, const HostQueries& query, const glm::vec3& q) {
  bool any_include = false, included = false;
  for (std::size_t zi = 0; zi < scene.zones.size(); ++zi) {
    const Zone& z = scene.zones[zi];
    const bool in = query.inside_shape(static_cast<int>(zi), q);
    if (in && (z.kind == Zone::Kind::Exclude || z.kind == Zone::Kind::Repel)) return false;
    if (z.kind == Zone::Kind::Include) {
      any_include = true;
      included = included || in;
    }
  }
  return !any_include || included;
}

}  // namespace growbench::colonization
