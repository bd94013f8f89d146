// The surface the vines grow on, seen both ways: as triangles in 3D and as their images in texture (UV)
// space. It answers where a UV point lies on the mesh, where a 3D point lies in UV, and walks a straight
// line on the surface from a point, across triangle edges and, through the mesh's adjacency over shared
// 3D positions, across UV seams onto the chart on the other side.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "scenes/scene.hpp"

namespace growbench::vines {

// A point on the surface: a triangle and barycentric coordinates (w.r.t. its corners 0, 1, 2).
struct Location {
  std::uint32_t tri = 0;
  glm::vec3 bary{1.0f, 0.0f, 0.0f};
};

// A straight piece of a walk inside one UV chart.
struct UvPiece {
  glm::vec2 a{0.0f}, b{0.0f};
};

struct Walk {
  Location end;
  float length = 0.0f;   // surface distance covered (less than asked when the walk was stopped)
  bool stopped = false;  // by a boundary, by a seam (when not crossing them) or by a degenerate triangle
  int seams = 0;         // UV seams crossed
  // The walk in UV, in order (for drawing): a piece for each run of triangles it crossed in a straight
  // line in UV, so one for most steps, and a new one at every seam.
  std::vector<UvPiece> pieces;
};

class Surface {
 public:
  // A scene mesh with texture coordinates (mesh.has_uvs()). Positions are welded by exact equality, so
  // a mesh whose seams duplicate vertices is still connected across them. Texture coordinates beyond
  // the unit square (tiled, UDIM-like or negative layouts) are fitted into it: their bounding box is
  // moved to the origin and scaled uniformly, which keeps charts apart and their shapes (see uv_rect).
  explicit Surface(const TriangleMesh& mesh);
  // The unit square as two triangles spanning origin, origin + u_axis, origin + u_axis + v_axis.
  static Surface canvas(const glm::vec3& origin, const glm::vec3& u_axis, const glm::vec3& v_axis);

  [[nodiscard]] std::size_t triangle_count() const { return corners_.size(); }
  [[nodiscard]] glm::vec3 position(const Location& l) const;
  [[nodiscard]] glm::vec2 uv(const Location& l) const;
  [[nodiscard]] glm::vec3 normal(std::uint32_t tri) const { return normal_[tri]; }
  [[nodiscard]] std::uint32_t chart(std::uint32_t tri) const { return chart_[tri]; }
  [[nodiscard]] std::size_t chart_count() const { return charts_; }
  // Surface area over UV area of a triangle (0 for a triangle of no UV area).
  [[nodiscard]] float area_ratio(std::uint32_t tri) const { return ratio_[tri]; }
  // The same over the whole surface (the triangles with UV area): total surface area / total UV area.
  [[nodiscard]] double mean_area_ratio() const { return mean_ratio_; }
  [[nodiscard]] double surface_area() const { return surface_area_; }
  [[nodiscard]] double uv_area() const { return uv_area_; }
  // Where the unit square lies in the mesh's own texture coordinates: its corner and side. (0, 0) and 1
  // unless the mesh's layout went beyond the unit square and was fitted into it.
  [[nodiscard]] glm::vec2 uv_origin() const { return uv_origin_; }
  [[nodiscard]] float uv_side() const { return uv_side_; }
  [[nodiscard]] bool uv_fitted() const { return uv_side_ != 1.0f || uv_origin_ != glm::vec2(0.0f); }
  // A point of the unit square in the mesh's own texture coordinates, and back (identities unless fitted).
  [[nodiscard]] glm::vec2 mesh_uv(const glm::vec2& uv) const { return uv_origin_ + uv_side_ * uv; }
  [[nodiscard]] glm::vec2 square_uv(const glm::vec2& mesh) const { return (mesh - uv_origin_) / uv_side_; }
  // The 3D image of a UV direction at a triangle (d/du, d/dv applied to it), not normalised.
  [[nodiscard]] glm::vec3 uv_to_3d(std::uint32_t tri, const glm::vec2& d) const;
  // The UV direction whose 3D image is the tangential part of d (least squares), not normalised.
  [[nodiscard]] glm::vec2 to_uv(std::uint32_t tri, const glm::vec3& d) const;

  // The triangle whose UV image holds uv (the lowest index where charts overlap); none outside them all.
  [[nodiscard]] std::optional<Location> locate(const glm::vec2& uv) const;
  // The closest point of the surface to p (exhaustive: for a few roots, not for growth).
  [[nodiscard]] Location closest(const glm::vec3& p) const;
  // Walks `length` along the surface from `from`, starting along d's tangential part. With cross_seams,
  // an edge whose two triangles lie apart in UV is crossed like any other; without, the walk stops there.
  [[nodiscard]] Walk walk(const Location& from, const glm::vec3& d, float length, bool cross_seams) const;
  // The same into `out`, reusing its memory (a grower's step, thousands per iteration).
  void walk(const Location& from, const glm::vec3& d, float length, bool cross_seams, Walk& out) const;

 private:
  Surface() = default;
  void fit_uvs();  // a layout beyond the unit square into it (uv_origin_, uv_side_)
  void build();    // everything derived from corners_, uv_ and pos_
  void build_adjacency();
  void build_uv_grid();
  [[nodiscard]] bool is_seam(std::uint32_t tri, int edge) const;

  std::vector<glm::vec3> pos_;                // welded positions
  std::vector<glm::uvec3> corners_;           // into pos_
  std::vector<std::array<glm::vec2, 3>> uv_;  // per triangle corner, in the unit square
  glm::vec2 uv_origin_{0.0f};                 // the mesh's texture coordinates = uv_origin_ + uv_side_ * uv_
  float uv_side_ = 1.0f;
  std::vector<glm::vec3> normal_;
  std::vector<float> ratio_;
  // Across edge k of triangle t (from corner k to corner k+1): the neighbour and its edge, or -1.
  std::vector<std::array<std::int32_t, 3>> next_tri_;
  std::vector<std::array<std::int8_t, 3>> next_edge_;
  std::vector<std::uint32_t> chart_;
  std::size_t charts_ = 0;
  double mean_ratio_ = 1.0, surface_area_ = 0.0, uv_area_ = 0.0;
  // Point location in UV: a grid over the unit square (and the charts' bounds beyond it), cell ->
  // the triangles whose UV bounds touch it.
  glm::vec2 grid_min_{0.0f}, grid_cell_{1.0f};
  int grid_n_ = 1;
  std::vector<std::uint32_t> grid_start_, grid_tris_;
};

}  // namespace growbench::vines
