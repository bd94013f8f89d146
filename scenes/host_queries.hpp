// The scene queries the plugin ABI's host table offers (include/growbench/plugin.h), as a C++
// interface. An algorithm that asks the scene only these builds both into the binary (DirectQueries,
// over the SceneQuery) and, from the same source, as a plugin (over the host's C table). Each call is
// batched over an array, safe for concurrent use, and a pure function of its input; the single-point
// forms are batches of one.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>

#include <glm/glm.hpp>

#include "scenes/scene_query.hpp"

namespace growbench {

// The envelope's index for inside_shape(); zones are 0, 1, ...
inline constexpr int kEnvelopeShape = -1;

struct Ray {
  glm::vec3 origin{0.0f}, direction{0.0f};
  float tmin = 0.0f, tmax = std::numeric_limits<float>::infinity();
};

class HostQueries {
 public:
  virtual ~HostQueries() = default;
  [[nodiscard]] virtual bool has_sdf() const = 0;
  virtual void closest_points(std::span<const glm::vec3> p, float max_distance, bool climbable_only,
                              std::span<ClosestHit> out) const = 0;
  virtual void rays(std::span<const Ray> r, std::span<RayHit> out) const = 0;
  virtual void occluded(std::span<const Ray> r, std::span<std::uint8_t> out) const = 0;
  // Either of `distance` and `gradient` may be empty: only the other is computed. Throws InputError
  // when the scene has no distance field.
  virtual void signed_distance(std::span<const glm::vec3> p, std::span<float> distance,
                               std::span<glm::vec3> gradient) const = 0;
  virtual void inside(std::span<const glm::vec3> p, std::span<std::uint8_t> out) const = 0;
  // `shape`: kEnvelopeShape or a zone's index; a shape the scene lacks contains nothing.
  virtual void inside_shape(int shape, std::span<const glm::vec3> p, std::span<std::uint8_t> out) const = 0;
  virtual void sample_surface(std::uint64_t seed, std::uint64_t first, std::span<SurfaceSample> out) const = 0;
  virtual void light_visible(std::span<const glm::vec3> p, float bias, std::span<std::uint8_t> out) const = 0;

  // Batches of one.
  [[nodiscard]] bool inside(const glm::vec3& p) const {
    std::uint8_t r = 0;
    inside({&p, 1}, {&r, 1});
    return r != 0;
  }
  [[nodiscard]] bool inside_shape(int shape, const glm::vec3& p) const {
    std::uint8_t r = 0;
    inside_shape(shape, {&p, 1}, {&r, 1});
    return r != 0;
  }
  [[nodiscard]] float signed_distance(const glm::vec3& p) const {
    float d = 0.0f;
    signed_distance({&p, 1}, {&d, 1}, {});
    return d;
  }
  [[nodiscard]] glm::vec3 gradient(const glm::vec3& p) const {
    glm::vec3 g(0.0f);
    signed_distance({&p, 1}, {}, {&g, 1});
    return g;
  }
  [[nodiscard]] SurfaceSample sample_surface(std::uint64_t seed, std::uint64_t index) const {
    SurfaceSample s;
    sample_surface(seed, index, {&s, 1});
    return s;
  }
};

// The queries answered by the scene's own SceneQuery, in the process.
class DirectQueries final : public HostQueries {
 public:
  explicit DirectQueries(const SceneQuery& query) : q_(query) {}
  [[nodiscard]] bool has_sdf() const override { return q_.has_sdf(); }
  void closest_points(std::span<const glm::vec3> p, float max_distance, bool climbable_only,
                      std::span<ClosestHit> out) const override;
  void rays(std::span<const Ray> r, std::span<RayHit> out) const override;
  void occluded(std::span<const Ray> r, std::span<std::uint8_t> out) const override;
  void signed_distance(std::span<const glm::vec3> p, std::span<float> distance,
                       std::span<glm::vec3> gradient) const override;
  void inside(std::span<const glm::vec3> p, std::span<std::uint8_t> out) const override;
  void inside_shape(int shape, std::span<const glm::vec3> p, std::span<std::uint8_t> out) const override;
  void sample_surface(std::uint64_t seed, std::uint64_t first, std::span<SurfaceSample> out) const override;
  void light_visible(std::span<const glm::vec3> p, float bias, std::span<std::uint8_t> out) const override;

 private:
  const SceneQuery& q_;
};

}  // namespace growbench
