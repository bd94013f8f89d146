#include "scenes/host_queries.hpp"

namespace growbench {

void DirectQueries::closest_points(std::span<const glm::vec3> p, float max_distance, bool climbable_only,
                                   std::span<ClosestHit> out) const {
  for (std::size_t i = 0; i < p.size(); ++i) out[i] = q_.closest_point(p[i], max_distance, climbable_only);
}

void DirectQueries::rays(std::span<const Ray> r, std::span<RayHit> out) const {
  for (std::size_t i = 0; i < r.size(); ++i) out[i] = q_.ray(r[i].origin, r[i].direction, r[i].tmax, r[i].tmin);
}

void DirectQueries::occluded(std::span<const Ray> r, std::span<std::uint8_t> out) const {
  for (std::size_t i = 0; i < r.size(); ++i)
    out[i] = q_.occluded(r[i].origin, r[i].direction, r[i].tmax, r[i].tmin) ? 1 : 0;
}

void DirectQueries::signed_distance(std::span<const glm::vec3> p, std::span<float> distance,
                                    std::span<glm::vec3> gradient) const {
  if (!q_.has_sdf()) throw InputError("the scene has no distance field");
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!distance.empty()) distance[i] = q_.signed_distance(p[i]);
    if (!gradient.empty()) gradient[i] = q_.gradient(p[i]);
  }
}

void DirectQueries::inside(std::span<const glm::vec3> p, std::span<std::uint8_t> out) const {
  for (std::size_t i = 0; i < p.size(); ++i) out[i] = q_.inside(p[i]) ? 1 : 0;
}

void DirectQueries::inside_shape(int shape, std::span<const glm::vec3> p, std::span<std::uint8_t> out) const {
  const Scene& s = q_.scene();
  const Shape* sh = nullptr;
  if (shape == kEnvelopeShape && s.envelope) sh = &*s.envelope;
  if (shape >= 0 && static_cast<std::size_t>(shape) < s.zones.size())
    sh = &s.zones[static_cast<std::size_t>(shape)].shape;
  for (std::size_t i = 0; i < p.size(); ++i) out[i] = sh && q_.inside_shape(*sh, p[i]) ? 1 : 0;
}

void DirectQueries::sample_surface(std::uint64_t seed, std::uint64_t first, std::span<SurfaceSample> out) const {
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = q_.sample_surface(seed, first + i);
}

void DirectQueries::light_visible(std::span<const glm::vec3> p, float bias, std::span<std::uint8_t> out) const {
  for (std::size_t i = 0; i < p.size(); ++i) out[i] = q_.light_visible(p[i], bias) ? 1 : 0;
}

}  // namespace growbench
