// nanoflann kd-trees over a std::vector<glm::vec3> (the one adaptor every module uses).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
// GCC 12 reports a false -Wmaybe-uninitialized inside nanoflann's dynamic index (root_bbox of trees it
// copies before building them); the warning is about the library's header, so it is silenced for it only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <nanoflann.hpp>
#pragma GCC diagnostic pop

namespace growbench {

// Points by reference: nanoflann keeps a reference to the adaptor, so the adaptor (and the vector it
// points to) must outlive the tree.
struct Vec3Cloud {
  const std::vector<glm::vec3>* pts = nullptr;
  [[nodiscard]] std::size_t kdtree_get_point_count() const { return pts->size(); }
  [[nodiscard]] float kdtree_get_pt(std::size_t i, std::size_t d) const { return (*pts)[i][static_cast<int>(d)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};

using Vec3Tree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Vec3Cloud>, Vec3Cloud, 3, std::uint32_t>;
using Vec3DynamicTree = nanoflann::KDTreeSingleIndexDynamicAdaptor<nanoflann::L2_Simple_Adaptor<float, Vec3Cloud>,
                                                                   Vec3Cloud, 3, std::uint32_t>;

// Visits the points of `tree` closer than `radius` to `centre`: visit(index, d2) gets each with its
// squared distance as nanoflann computes it, in the tree's order, and returns false to end the search.
// Nothing is listed, so a search allocates nothing.
template <class Visit>
struct KdVisitor {
  float radius2;
  Visit visit;
  [[nodiscard]] float worstDist() const { return radius2; }
  [[nodiscard]] bool full() const { return true; }
  [[nodiscard]] std::size_t size() const { return 0; }
  bool addPoint(float d2, std::uint32_t i) { return visit(i, d2); }
};
template <class Tree, class Visit>
void kd_visit_within(const Tree& tree, const glm::vec3& centre, float radius, Visit visit) {
  KdVisitor<Visit> v{radius * radius, std::move(visit)};
  tree.radiusSearchCustomCallback(&centre.x, v, nanoflann::SearchParams(32, 0.0f, false));
}

}  // namespace growbench
