// Conversions between the plugin ABI's plain structs (include/growbench/plugin.h) and the project's
// types, shared by the host's side (plugin_algorithm.cpp) and a built-in's plugin side
// (builtin_plugin.cpp), so the two directions cannot drift apart.
#pragma once

#include <span>
#include <type_traits>

#include <glm/glm.hpp>

#include "growbench/plugin.h"
#include "scenes/host_queries.hpp"

namespace growbench::abi {

// glm's vectors and the ABI's are the same three floats, so arrays pass without a copy.
static_assert(sizeof(glm::vec3) == sizeof(growbench_vec3) && std::is_standard_layout_v<glm::vec3>);
static_assert(sizeof(glm::uvec3) == 3 * sizeof(std::uint32_t));

inline growbench_vec3 of(const glm::vec3& p) {
  return {p.x, p.y, p.z};
}
inline glm::vec3 of(const growbench_vec3& p) {
  return {p.x, p.y, p.z};
}
inline const growbench_vec3* of(const glm::vec3* p) {
  return reinterpret_cast<const growbench_vec3*>(p);
}
inline std::span<const glm::vec3> points(const growbench_vec3* p, std::uint64_t n) {
  return {reinterpret_cast<const glm::vec3*>(p), static_cast<std::size_t>(n)};
}

inline growbench_closest_hit of(const ClosestHit& h) {
  return {h.found ? 1 : 0, of(h.point), of(h.normal), h.distance, h.mesh, h.triangle};
}
inline ClosestHit of(const growbench_closest_hit& h) {
  return {h.found != 0, of(h.point), of(h.normal), h.distance, h.mesh, h.triangle};
}
inline growbench_ray_hit of(const RayHit& h) {
  return {h.hit ? 1 : 0, h.t, of(h.point), of(h.normal), h.mesh, h.triangle};
}
inline RayHit of(const growbench_ray_hit& h) {
  return {h.hit != 0, h.t, of(h.point), of(h.normal), h.mesh, h.triangle};
}
inline growbench_ray of(const Ray& r) {
  return {of(r.origin), of(r.direction), r.tmin, r.tmax};
}
inline Ray of(const growbench_ray& r) {
  return {of(r.origin), of(r.direction), r.tmin, r.tmax};
}
inline growbench_surface_sample of(const SurfaceSample& s) {
  return {of(s.position), of(s.normal), s.mesh, s.triangle};
}
inline SurfaceSample of(const growbench_surface_sample& s) {
  return {of(s.position), of(s.normal), s.mesh, s.triangle};
}

// Each element of `from` converted into `to` (the same length).
template <class From, class To>
void convert(std::span<const From> from, std::span<To> to) {
  for (std::size_t i = 0; i < from.size(); ++i) to[i] = of(from[i]);
}

}  // namespace growbench::abi
