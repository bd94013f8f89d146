// Small geometric building blocks for scenes and tests.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "scenes/scene.hpp"

namespace growbench::geom {

// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection, 5.1.5).
glm::vec3 closest_point_on_triangle(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b,
                                    const glm::vec3& c);

// Per vertex, the sum of its faces' (b - a) x (c - a): area-weighted, not normalised (zero for a vertex
// no face uses).
std::vector<glm::vec3> vertex_normal_sums(const TriangleMesh& mesh);

// Closed, outward-facing primitive meshes.
TriangleMesh make_box(const std::string& name, const glm::vec3& min, const glm::vec3& max);
TriangleMesh make_cylinder(const std::string& name, const glm::vec3& base, const glm::vec3& top,
                           float radius_base, float radius_top, int sides);
TriangleMesh make_icosphere(const std::string& name, const glm::vec3& center, float radius,
                            int subdivisions);

// Closes the holes of a nearly closed mesh (boundary edges at most `max_boundary_fraction` of all
// edges) by fanning each boundary loop to its centroid. Returns whether the mesh is closed afterwards;
// leaves it unchanged when the boundary is not a set of simple loops or is too large.
bool fill_small_holes(TriangleMesh& mesh, double max_boundary_fraction = 0.01);

glm::mat4 trs(const glm::vec3& translate, const glm::vec3& rotate_deg, const glm::vec3& scale);

}  // namespace growbench::geom
