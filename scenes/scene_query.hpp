// Spatial queries on a scene, built once and safe for concurrent use from many threads.
//
//  * Embree BVH: closest point (rtcPointQuery, optionally bounded), ray cast, occlusion, light visibility.
//  * OpenVDB narrow-band level set: signed distance, gradient.
//  * The exact inside test, which every judgement of "inside a solid" goes through (see inside()).
//
// Solids. A mesh is solid when it is closed: every edge shared by two opposite triangles. Scans with a
// few small holes are sealed when they are loaded (scene_io), so the solid an algorithm collides with
// (Embree's triangles) is the solid the distance field and the metrics judge. An open mesh (a lone wall
// quad) has no inside: it contributes an unsigned distance, so points near it are never "inside".
//
// Signed distance. Each solid becomes a level set (negative inside) and the scene's field is their CSG
// union, so touching or overlapping solids need no boolean meshing. Within the narrow band (band_voxels
// on each side) the value is OpenVDB's trilinear sample; beyond it the magnitude is Embree's exact
// closest-point distance and the sign is the band's (inside tiles are negative), so distances are right
// everywhere, not clamped at the band. The trilinear value is an approximation near the surface: in a
// concave crease it reads negative a little outside. So its sign is not an inside test; inside() is.
//
// Lifetime: the query refers to the scene's meshes; the scene must outlive it.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "scenes/scene.hpp"

namespace growbench {

struct SceneQueryOptions {
  float voxel_size = 0.0f;  // 0: the meshes' bounding-box diagonal / 256
  float band_voxels = 3.0f;
  bool build_sdf = true;  // false: only Embree (signed_distance etc. then throw)
};

struct ClosestHit {
  bool found = false;
  glm::vec3 point{0.0f};
  glm::vec3 normal{0.0f};  // unit face normal of the closest triangle (outward for closed meshes)
  float distance = std::numeric_limits<float>::infinity();
  std::uint32_t mesh = 0, triangle = 0;
};

struct RayHit {
  bool hit = false;
  float t = std::numeric_limits<float>::infinity();
  glm::vec3 point{0.0f};
  glm::vec3 normal{0.0f};  // unit face normal (as wound; not flipped toward the ray)
  std::uint32_t mesh = 0, triangle = 0;
};

struct SurfaceSample {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};
  std::uint32_t mesh = 0, triangle = 0;
};

class SdfGrid;      // OpenVDB, in sdf.cpp only
class HostQueries;  // scenes/host_queries.hpp

// An Embree BVH over caller-given boxes (user geometry), for "which of these regions hold p" and
// "which does this segment pass through" queries: the ivy's Luft adhesion asks which triangles'
// extruded prisms contain a point, which a ball query over the triangles answers only by visiting
// every triangle within the adhesion distance; its collision test asks whether a segment crosses any
// triangle. Both are traversed as rays (a point is a ray of length zero), Embree's fastest traversal:
// on the bunny a ray costs a fraction of a ball query (rtcPointQuery) of the same reach. Built by
// SceneQuery::box_index on its device; safe for concurrent queries.
class BoxIndex {
 public:
  ~BoxIndex();
  BoxIndex(const BoxIndex&) = delete;
  BoxIndex& operator=(const BoxIndex&) = delete;
  // Called with the index of a box (into the boxes given); returning true ends the query.
  using Visitor = bool (*)(void* user, std::uint32_t id);
  // Visits every box that contains p, and possibly a few that do not (Embree's leaves hold several
  // boxes): the visitor tests its own rule.
  void visit_containing(const glm::vec3& p, Visitor visit, void* user) const {
    visit_segment(p, glm::vec3(0.0f), visit, user);
  }
  // Visits every box the segment from o to o + d passes through (and possibly a few more). Boxes
  // touched only within rounding of their faces may be missed: pad the boxes if that matters.
  void visit_segment(const glm::vec3& o, const glm::vec3& d, Visitor visit, void* user) const;
  [[nodiscard]] std::size_t size() const { return boxes_.size(); }

 private:
  friend class SceneQuery;
  struct Impl;
  BoxIndex(void* device, std::vector<Aabb> boxes);
  std::vector<Aabb> boxes_;
  std::unique_ptr<Impl> impl_;
};

// An Embree scene of geometry that is not the scene's: a plant's branches as round capsules and its
// organs and polygons as triangles, for "does the plant itself block this ray" (self-shadowing). Each
// triangle has an owner (an organ index, or kNoOwner); a ray may ignore one owner, the leaf it leaves
// from. Built by SceneQuery::occluder on its device; safe for concurrent queries.
class Occluder {
 public:
  static constexpr std::uint32_t kNoOwner = 0xFFFFFFFFu;
  struct Capsule {  // a cone from a (radius ra) to b (radius rb) with spheres at both ends
    glm::vec3 a{0.0f}, b{0.0f};
    float ra = 0.0f, rb = 0.0f;
  };
  struct Triangle {
    glm::vec3 v[3]{};
    std::uint32_t owner = kNoOwner;
  };
  ~Occluder();
  Occluder(const Occluder&) = delete;
  Occluder& operator=(const Occluder&) = delete;
  // Whether anything but `ignore`'s triangles lies on the ray o + t d, t in [tmin, tmax].
  [[nodiscard]] bool occluded(const glm::vec3& o, const glm::vec3& d, float tmax, std::uint32_t ignore = kNoOwner,
                              float tmin = 0.0f) const;

 private:
  friend class SceneQuery;
  struct Impl;
  Occluder(void* device, std::vector<Capsule> capsules, std::vector<Triangle> triangles);
  std::vector<std::uint32_t> owners_;
  std::unique_ptr<Impl> impl_;
};

class SceneQuery {
 public:
  explicit SceneQuery(const Scene& scene, SceneQueryOptions options = {});
  ~SceneQuery();
  SceneQuery(const SceneQuery&) = delete;
  SceneQuery& operator=(const SceneQuery&) = delete;

  // Closest surface point within max_distance (not found beyond it). climbable_only: among the climbable
  // meshes only (when the scene marks any; otherwise all meshes count).
  [[nodiscard]] ClosestHit closest_point(const glm::vec3& p,
                                         float max_distance = std::numeric_limits<float>::infinity(),
                                         bool climbable_only = false) const;
  // First hit along origin + t dir for t in (tmin, tmax); dir need not be normalised (t is in its units).
  // Calls `visit` for every triangle in a BVH leaf that comes within `radius` of p (an Embree point
  // query: a conservative superset of the triangles within radius; a triangle may be visited twice
  // when the BVH split it). The visitor may shrink *radius to prune the rest of the traversal. For
  // queries with their own per-triangle rule (the ivy's Luft adhesion and collision candidates).
  using TriangleVisitor = void (*)(void* user, std::uint32_t mesh, std::uint32_t triangle, float* radius);
  void visit_near(const glm::vec3& p, float radius, TriangleVisitor visit, void* user) const;
  // An index over `boxes` (an empty box never contains anything).
  [[nodiscard]] std::unique_ptr<BoxIndex> box_index(std::vector<Aabb> boxes) const;
  [[nodiscard]] std::unique_ptr<Occluder> occluder(std::vector<Occluder::Capsule> capsules,
                                                   std::vector<Occluder::Triangle> triangles) const;
  [[nodiscard]] RayHit ray(const glm::vec3& origin, const glm::vec3& dir,
                           float tmax = std::numeric_limits<float>::infinity(), float tmin = 0.0f) const;
  [[nodiscard]] bool occluded(const glm::vec3& origin, const glm::vec3& dir,
                              float tmax = std::numeric_limits<float>::infinity(), float tmin = 0.0f) const;
  // Whether p sees the scene's light (a ray towards it, offset by `bias` to leave the surface).
  [[nodiscard]] bool light_visible(const glm::vec3& p, float bias = 1e-4f) const;

  [[nodiscard]] float signed_distance(const glm::vec3& p) const;
  // The level set alone, for per-particle work every step: one read of eight voxels, no Embree
  // fallback. Within the narrow band, `distance` is the trilinear signed distance and `gradient` its
  // unit gradient (outwards). Beyond it, in_band is false, |distance| is the band width (the true
  // distance is at least that) and the gradient is zero.
  struct BandSample {
    float distance = 0.0f;
    glm::vec3 gradient{0.0f};
    bool in_band = false;
  };
  [[nodiscard]] BandSample band_sample(const glm::vec3& p) const;
  // Unit gradient of the signed distance (points away from the nearest surface, outwards).
  [[nodiscard]] glm::vec3 gradient(const glm::vec3& p) const;
  // Whether p lies inside a solid; the surface itself, to within a micrometre per metre of |p| (a
  // float's rounding), is outside. Exact: the distance field decides only
  // where it reads beyond inside_screen() from zero, which its error cannot cross (the voxels hold
  // distances, so the trilinear value is within sqrt(3)/2 voxel of the truth; the screen is two voxels).
  // Nearer, each solid whose bounds hold p decides by its closest point: p is inside when it lies behind
  // the angle-weighted pseudonormal of the face, edge or vertex that point is on (Baerentzen & Aanaes
  // 2005), exact on closed meshes at edges and vertices alike. Without a distance field, every point
  // takes the exact test.
  [[nodiscard]] bool inside(const glm::vec3& p) const;
  // The exact test alone for one mesh (false for a mesh that is not solid).
  [[nodiscard]] bool inside_mesh(std::uint32_t mesh, const glm::vec3& p) const;
  // |signed field| at or beyond which inside() trusts the field's sign.
  [[nodiscard]] float inside_screen() const;
  // Inside a shape (envelope or zone). Boxes and ellipsoids analytically; mesh shapes by ray parity.
  [[nodiscard]] bool inside_shape(const Shape& shape, const glm::vec3& p) const;

  // Area-weighted uniform sample on the climbable meshes (all meshes if none is climbable): a pure
  // function of (seed, index).
  [[nodiscard]] SurfaceSample sample_surface(std::uint64_t seed, std::uint64_t index) const;
  [[nodiscard]] double sampled_area() const { return total_area_; }

  [[nodiscard]] const Scene& scene() const { return scene_; }
  // These queries through the plugin ABI's interface (scenes/host_queries.hpp). Inline, so that an
  // algorithm built as a plugin, which never has a SceneQuery, links without this file.
  [[nodiscard]] const HostQueries& host_queries() const { return *host_queries_; }
  [[nodiscard]] float voxel_size() const { return voxel_size_; }
  [[nodiscard]] float band_width() const { return voxel_size_ * options_.band_voxels; }
  [[nodiscard]] bool has_sdf() const { return sdf_ != nullptr; }
  [[nodiscard]] double bvh_build_seconds() const { return bvh_seconds_; }
  [[nodiscard]] double sdf_build_seconds() const { return sdf_seconds_; }
  [[nodiscard]] std::size_t sdf_active_voxels() const;
  // Per mesh: whether it is a solid with an inside (closed).
  [[nodiscard]] const std::vector<bool>& mesh_solid() const { return solid_; }

 private:
  // Refuses a distance field OpenVDB cannot represent (InputError) or that would need more memory than
  // the process may take (OutOfMemoryError), before building it. `given`: the voxel size is the user's.
  void check_sdf_size(const std::vector<const TriangleMesh*>& meshes, const Aabb& bounds, bool given) const;
  struct Embree;
  struct VertexIndex;
  struct Solid;
  bool inside_exact(const glm::vec3& p) const;
  const Scene& scene_;
  SceneQueryOptions options_;
  std::unique_ptr<Embree> embree_;
  std::unique_ptr<SdfGrid> sdf_;
  std::unique_ptr<VertexIndex> vertices_;
  std::vector<bool> solid_;
  std::vector<std::unique_ptr<Solid>> solids_;  // per mesh; null when it is not solid
  std::vector<bool> not_climbable_;             // per mesh; empty when no mesh is marked climbable
  float voxel_size_ = 0.0f;
  double bvh_seconds_ = 0.0, sdf_seconds_ = 0.0;
  // Surface sampling: cumulative areas over (mesh, triangle) pairs.
  std::vector<double> cdf_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> cdf_tri_;
  double total_area_ = 0.0;
  std::unique_ptr<HostQueries> host_queries_;
};

}  // namespace growbench
