// The world plants grow in: meshes, seeds, light, envelope, zones, camera.
// Units are metres, Y is up, angles are degrees.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/errors.hpp"

namespace growbench {

// The farthest a scene's coordinates may lie from the origin, in metres. Beyond it a float keeps no
// useful precision for growth, and far beyond it Embree refuses the rays (it aborts at about 1.8e18);
// scene files, meshes, lights and --seed-at are refused past it, naming what lies there.
inline constexpr float kMaxCoordinate = 1e9f;

struct Aabb {
  glm::vec3 min{std::numeric_limits<float>::max()};
  glm::vec3 max{-std::numeric_limits<float>::max()};
  void extend(const glm::vec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void extend(const Aabb& b) {
    extend(b.min);
    extend(b.max);
  }
  [[nodiscard]] bool empty() const { return min.x > max.x; }
  [[nodiscard]] glm::vec3 size() const { return empty() ? glm::vec3(0.0f) : max - min; }
  [[nodiscard]] glm::vec3 center() const { return 0.5f * (min + max); }
  [[nodiscard]] bool contains(const glm::vec3& p) const {
    return glm::all(glm::greaterThanEqual(p, min)) && glm::all(glm::lessThanEqual(p, max));
  }
};

// A triangle mesh in world space (transforms are applied when the scene is built or loaded).
struct TriangleMesh {
  std::string name;
  std::vector<glm::vec3> vertices;
  std::vector<glm::uvec3> triangles;
  // Plants may climb it and surface attraction points are sampled on it (the ground is not climbable).
  bool climbable = true;
  // Drawn in renders and exported scenes. false: a collision-only object, one plants collide with and
  // climb but no picture shows (the Hyphae notes' collision object, a guide beside the visible mesh).
  bool visible = true;
  // Texture coordinates (OBJ `vt`), when the mesh has them: corner k of triangles[i] has
  // uvs[uv_triangles[i][k]]. Both are empty when it has none. v points up the image (OpenGL's and OBJ's
  // convention: the image's top row is v = 1).
  std::vector<glm::vec2> uvs;
  std::vector<glm::uvec3> uv_triangles;

  [[nodiscard]] bool has_uvs() const { return !uv_triangles.empty(); }

  [[nodiscard]] Aabb bounds() const;
  [[nodiscard]] double area() const;
  // True when every edge is shared by exactly two triangles with opposite orientation.
  [[nodiscard]] bool is_closed() const;
  void append(const TriangleMesh& other);
  void transform(const glm::mat4& m);
};

struct Seed {
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, 1.0f, 0.0f};
  int start_step = 0;  // the step at which this seed starts growing (0: at once)
};

struct Light {
  enum class Kind { Sun, Point };
  Kind kind = Kind::Sun;
  glm::vec3 direction{0.3f, 1.0f, 0.5f};  // Sun: direction *towards* the light (normalised on use)
  glm::vec3 position{0.0f, 10.0f, 0.0f};  // Point: position
  // Direction from p towards the light, normalised.
  [[nodiscard]] glm::vec3 towards(const glm::vec3& p) const {
    return kind == Kind::Sun ? glm::normalize(direction) : glm::normalize(position - p);
  }
  // Distance from p to the light along towards(p) (infinite for the sun).
  [[nodiscard]] float distance(const glm::vec3& p) const {
    return kind == Kind::Sun ? std::numeric_limits<float>::infinity() : glm::length(position - p);
  }
};

// A simple solid used by envelopes and zones.
struct Shape {
  enum class Kind { Box, Sphere, Mesh };
  Kind kind = Kind::Box;
  glm::vec3 min{0.0f}, max{0.0f};  // Box
  glm::vec3 center{0.0f};          // Sphere (and ellipsoid radii via `radii`)
  glm::vec3 radii{1.0f};           // Sphere: radii per axis (an ellipsoid when they differ)
  TriangleMesh mesh;               // Mesh: a closed mesh

  [[nodiscard]] Aabb bounds() const;
  [[nodiscard]] double volume() const;  // exact for box and ellipsoid; for a mesh, by divergence theorem
  // Inside test for box and ellipsoid. Mesh shapes are tested by the SceneQuery (needs a ray cast).
  [[nodiscard]] bool contains_analytic(const glm::vec3& p) const;
};

struct Zone {
  enum class Kind { Attract, Repel, Include, Exclude };
  Kind kind = Kind::Attract;
  Shape shape;
  float strength = 1.0f;
};

struct Camera {
  glm::vec3 position{0.0f, 1.5f, 6.0f};
  glm::vec3 look_at{0.0f, 1.0f, 0.0f};
  float fov_deg = 45.0f;
};

struct Scene {
  std::string name;
  std::string source;  // "builtin:wall", a JSON path, or "mesh:PATH"
  std::vector<TriangleMesh> meshes;
  std::vector<Seed> seeds;
  Light light;
  std::optional<Shape> envelope;
  std::vector<Zone> zones;
  Camera camera;

  [[nodiscard]] Aabb bounds() const;
  // What lies beyond kMaxCoordinate ("seed 2 at (0, 1e+19, 0)"), or "" when nothing does.
  [[nodiscard]] std::string out_of_bounds() const;
  // Whether any mesh is climbable: a scene of ground alone (envelope) offers nothing to climb.
  [[nodiscard]] bool has_climbable() const;
  [[nodiscard]] std::size_t triangle_count() const;
  // A hash of everything that defines the scene's content (geometry, seeds, light, envelope, zones,
  // camera), as 16 hex digits. Two scenes with the same hash grow the same plants.
  [[nodiscard]] std::string content_hash() const;
};

}  // namespace growbench
