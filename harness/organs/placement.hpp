// The organ pass after growth (options.hpp): variation, then placement. Shared by every algorithm.
#pragma once

#include <array>
#include <cstdint>

#include "algorithms/plant.hpp"
#include "harness/organs/options.hpp"
#include "algorithms/organ_shapes.hpp"

namespace growbench {

struct PlacementCounts {
  std::uint64_t placed = 0;       // as grown (after variation)
  std::uint64_t fallen_back = 0;  // placed turned, smaller or as their fallback
  std::uint64_t dropped = 0;      // no candidate fitted
  struct Kind {
    std::uint64_t placed = 0, fallen_back = 0, dropped = 0;
  };
  std::array<Kind, 4> by_kind{};  // by OrganKind (the kind as grown)
};

// Scales, turns and tints each organ by counter-based draws from `seed` and its index (the same plant
// for any thread count), and alternates blooms when asked. Adds to plant.organ_shapes what it uses.
void vary_organs(Plant& plant, const OrganOptions& options, std::uint64_t seed);

// With placement=avoid: visits the organs in the plant's order and keeps each whose triangles come within
// no branch segment's radius but its stem's (the chain of segments from the branch point its node hangs
// from, those starting at its node, and the joint's collar: the part of the branch point's other segments
// no farther from it than the organ's node and their radius) and meet those of no organ kept before it
// (geom::triangles_overlap, the leaf_overlap metric's test, after oriented boxes); otherwise the first of
// its candidates that passes the same test (turned by +-turn_deg, pointed along its stem and so turned,
// at `shrink` of its size, its fallback); otherwise it is dropped.
// A k-d tree finds each organ's earlier neighbours in parallel; each organ is then decided, in parallel
// with others, once its earlier neighbours are, testing only against the candidates they took. The
// result is the in-order visit's, the same for any thread count. With placement=free, only counts.
PlacementCounts place_organs(Plant& plant, const OrganOptions& options, const OrganShape* custom_leaf = nullptr);

// An organ's oriented box: the shape's bounds in the organ's frame, scaled by its size and padded in
// every direction by more than the rounding of placing its vertices, so it holds them.
struct OrientedBox {
  glm::dvec3 centre{0.0}, axis[3]{}, half{0.0};
};
OrientedBox organ_box(const Organ& organ, const OrganShape& shape);
bool boxes_overlap(const OrientedBox& a, const OrientedBox& b);
// The orientation q turned by the least rotation that points its local +Z from `from` to `to`; q itself
// where the two points are too close to give a direction.
glm::quat pointed_along(const glm::quat& q, const glm::vec3& from, const glm::vec3& to);
// Whether the capsule from p to q with radius r meets the box.
bool capsule_meets_box(const glm::dvec3& p, const glm::dvec3& q, double r, const OrientedBox& box);

}  // namespace growbench
