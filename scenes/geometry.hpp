// Small geometric building blocks for scenes and tests.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scenes/scene.hpp"

namespace growbench::geom {

// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection, 5.1.5).
glm::vec3 closest_point_on_triangle(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);

// Distance between segments [p0,p1] and [q0,q1] (Ericson 5.1.9).
float segment_distance(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& q0, const glm::vec3& q1);

// Distance between segment [p,q] and triangle t: zero where the segment passes through the triangle;
// otherwise the least of its ends' distances to the triangle and its distances to the triangle's edges,
// where a segment and a triangle that do not meet come closest.
float segment_triangle_distance(const glm::vec3& p, const glm::vec3& q, const glm::vec3 (&t)[3]);

// The same in double precision, with the feature the point lies on: a vertex, the interior of an edge,
// or the face. The feature picks the pseudonormal that decides the side of p (SceneQuery's exact inside
// test); double precision keeps the point exact to far below a float's rounding even on long slivers,
// where the float version can be off by microns.
enum class TriangleFeature : std::uint8_t { VertexA, VertexB, VertexC, EdgeAB, EdgeBC, EdgeCA, Face };
struct TriangleFeaturePoint {
  glm::dvec3 point;
  TriangleFeature feature;
};
TriangleFeaturePoint closest_feature_on_triangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                                 const glm::dvec3& c);

// Whether two triangles share more than isolated points: they cross along a segment, or lie in one plane
// sharing area (Moller's interval test in double precision; coplanar pairs by clipping). Touching at a
// point, such as two leaves on one petiole, is not an overlap; lengths below 1e-7 of the larger
// triangle's size are taken as rounding.
bool triangles_overlap(const glm::vec3 (&a)[3], const glm::vec3 (&b)[3]);

// Per vertex, the sum of its faces' (b - a) x (c - a): area-weighted, not normalised (zero for a vertex
// no face uses).
std::vector<glm::vec3> vertex_normal_sums(const TriangleMesh& mesh);

// A mesh ready for smooth shading that keeps its creases (a render's and scene.glb's scene meshes): each
// triangle corner's normal is the area-weighted mean of the faces around its vertex that meet the corner's
// own face at less than kCreaseDeg, and a vertex whose corners get different normals is split. The
// triangles keep their order, so texture coordinates indexed by triangle still apply.
// Tessellated curves (a column's sides, the bunny) turn by much less than kCreaseDeg from face to face; a
// box's faces meet at 90 degrees and keep their edges.
constexpr float kCreaseDeg = 40.0f;
struct ShadedMesh {
  std::vector<glm::vec3> vertices, normals;
  std::vector<glm::uvec3> triangles;
};
ShadedMesh crease_shaded(const TriangleMesh& mesh);

// Closed, outward-facing primitive meshes.
TriangleMesh make_box(const std::string& name, const glm::vec3& min, const glm::vec3& max);
TriangleMesh make_cylinder(const std::string& name, const glm::vec3& base, const glm::vec3& top, float radius_base,
                           float radius_top, int sides);
TriangleMesh make_icosphere(const std::string& name, const glm::vec3& center, float radius, int subdivisions);

// Closes the holes of a nearly closed mesh (boundary edges at most `max_boundary_fraction` of all
// edges): each boundary loop is triangulated by ear clipping in its best-fit plane, or, when its
// projection there is not simple, fanned to its centroid. Returns whether the mesh is closed afterwards;
// leaves it unchanged when the boundary is not a set of simple loops or is too large.
bool fill_small_holes(TriangleMesh& mesh, double max_boundary_fraction = 0.01);

glm::mat4 trs(const glm::vec3& translate, const glm::vec3& rotate_deg, const glm::vec3& scale);

}  // namespace growbench::geom
