// Luft-style ivy (Thomas Luft, "An Ivy Generator", 2006-2008; Blender's IvyGen add-on ports it).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "algorithms/algorithm.hpp"
#include "algorithms/ivy/luft_rules.hpp"

namespace growbench {

namespace ivy {

constexpr std::uint32_t kNoTriangle = 0xFFFFFFFFu;

enum class AdhesionMode : std::uint8_t { Luft, Closest };
enum class CollisionMode : std::uint8_t { Luft, Blender };
enum class LeafMode : std::uint8_t { Luft, Blender, None };

// Parameters resolved to metres (units=relative multiplied through by R). Every value comes from the
// parameter table and the scene (make_config): no member has a default of its own.
struct Config {
  float radius;                     // R: the climbable meshes' bounding-sphere radius
  float step;                       // ivy size: length scale of one growth step
  float primary, random, adhesion;  // normalised to sum 1
  float gravity;
  float branching;         // a node branches when rand * w > this
  float leaf_probability;  // a leaf grows when rand * w > this
  float leaf_size;         // half the side of a leaf quad
  float branch_size;       // radius scale
  float max_float;
  float max_adhesion;
  double max_root_length;   // 0: unlimited
  double max_total_length;  // 0: unlimited
  AdhesionMode adhesion_mode;
  CollisionMode collision_mode;
  LeafMode leaf_mode;
  int max_depth;
  int branches_per_step;
  std::size_t max_roots;
  int smoothing_passes;
  int leaf_passes;
  float margin;  // slack added to query radii (1e-5 R)
};

// The max distance from the vertex centroid of the climbable meshes (all meshes when none is
// climbable) to one of their vertices.
float bounding_sphere_radius(const Scene& scene);
Config make_config(const Params& params, const Scene& scene);

// Triangle ids collected for one node's collision test: a fixed inline buffer that spills to the
// heap only for unusually many candidates (no per-node allocation in the common case, and the
// allocation count depends on the geometry only, never on threads).
class Candidates {
 public:
  void push(std::uint32_t id) {
    if (n_ < local_.size())
      local_[n_++] = id;
    else {
      if (heap_.empty()) heap_.assign(local_.begin(), local_.end());
      heap_.push_back(id);
      ++n_;
    }
  }
  // Sorted, without duplicates (a BVH with spatial splits may offer a triangle twice).
  std::span<const std::uint32_t> sorted_unique();
  [[nodiscard]] std::size_t size() const { return n_; }

 private:
  std::array<std::uint32_t, 64> local_{};
  std::vector<std::uint32_t> heap_;
  std::size_t n_ = 0;
};

// An adhesion answer computed ahead of its node (see Geometry::crosses_any).
struct Lookahead {
  glm::vec3 vector{0.0f};
  std::uint32_t hint = kNoTriangle;
  bool valid = false;
};

// The scene queries the growth needs; the Embree implementation is make_embree_geometry, the tests
// add a brute-force one over all triangles.
class Geometry {
 public:
  virtual ~Geometry() = default;
  // The adhesion vector at p. `hint` is the triangle that attracted the previous node of the root (or
  // kNoTriangle): offered first, it may bound the search without changing the answer. It returns
  // holding this node's target.
  virtual glm::vec3 adhesion(const glm::vec3& p, std::uint32_t& hint) const = 0;
  // Pushes every triangle that comes within `radius` of `centre` into `candidates`, and perhaps some
  // more whose bounds do, for the Luft collision test. (Embree's BVH may split a long triangle's bounds,
  // so one whose box reaches the ball while its surface does not can be left out.)
  virtual void gather(const glm::vec3& centre, float radius, Candidates& candidates) const = 0;
  // Whether Luft's collision rule finds any triangle that the segment o -> q crosses (entering it).
  // When none is, an implementation may also settle adhesion(q) on the way (at_q.valid): exactly
  // what adhesion(q, hint) would return and leave in hint.
  virtual bool crosses_any(const glm::vec3& o, const glm::vec3& q, Lookahead& at_q) const = 0;
  // Blender's collision: the first hit on the segment o -> o + d (t in [0, 1]), any side.
  virtual RayHit first_hit(const glm::vec3& o, const glm::vec3& d) const = 0;
};

std::unique_ptr<Geometry> make_embree_geometry(const SceneQuery& query, const TriangleTable& table,
                                               const Config& config);

// Luft's generator: one step() is one of his grow() iterations. Deterministic for any thread count:
// roots grow in parallel, the i-th alive root writing the step's i-th new node, so nodes are in root
// order whatever the thread count; every random draw is a pure function of (seed, root, node) or
// (seed, iteration, root).
class Grower {
 public:
  Grower(const Scene& scene, const Geometry& geometry, const TriangleTable& table, const Config& config,
         std::uint64_t seed);
  // One iteration; false once nothing more can grow (no root alive, or a length limit reached).
  bool step();
  // Luft's birth(): adhesion smoothing, branch radii, leaves.
  void finish();
  [[nodiscard]] const Plant& plant() const { return plant_; }
  [[nodiscard]] std::vector<std::pair<std::string, double>> stats() const;
  // Bytes held per plant node by the growth state (plant nodes + per-node arrays + root lists).
  [[nodiscard]] double state_bytes_per_node() const;

 private:
  struct Root {
    std::vector<std::uint32_t> nodes;  // plant node indices; [0] is the start (a branch root's parent node)
    glm::vec3 dir{0.0f, 1.0f, 0.0f};   // primary direction at the tip
    float first_floating = 0.0f;       // floating length of node [0] as this root sees it
    // The tip's state, kept here so that growing a root reads one record instead of four arrays.
    glm::vec3 tip{0.0f};
    float tip_length = 0.0f, tip_floating = 0.0f;
    std::uint32_t hint = kNoTriangle;  // the triangle that attracted the tip
    std::uint32_t id = 0;
    // The adhesion at the tip when the previous node's crossing test settled it (a valid ahead
    // carries its hint in `hint`).
    glm::vec3 ahead{0.0f};
    bool ahead_valid = false;
    std::uint16_t depth = 0;
  };
  struct Grown {
    glm::vec3 pos, dir, adhesion;
    float length, floating;
    std::uint32_t reflections, hint;
    bool climbing, floated_out, collision_death;  // the root lives on unless one of the last two
    Lookahead ahead;                              // the adhesion at pos, when already known
  };
  struct Outcome {  // what the serial part of a step needs of a grown node
    float segment, length;
    std::uint32_t reflections;
    bool climbing, floated_out, collision_death;
  };
  [[nodiscard]] float length_at(const Root& r, std::size_t k) const { return k == 0 ? 0.0f : length_[r.nodes[k]]; }
  [[nodiscard]] float floating_at(const Root& r, std::size_t k) const {
    return k == 0 ? r.first_floating : floating_[r.nodes[k]];
  }
  void add_seed_roots();
  Grown grow_one(const Root& r) const;
  // Luft's radius before birth() knows the root's length: the tip value, 1.3 x base.
  [[nodiscard]] float base_radius(int depth) const {
    return (1.0f / static_cast<float>(depth + 1) + 1.0f) * cfg_.branch_size;
  }
  [[nodiscard]] std::ptrdiff_t pick_branch_node(const Root& r) const;
  [[nodiscard]] bool limits_reached() const;

  const Scene& scene_;
  const Geometry& geometry_;
  const TriangleTable& table_;
  Config cfg_;
  std::uint64_t seed_;
  Plant plant_;
  std::vector<glm::vec3> adhesion_;  // per plant node
  std::vector<float> length_, floating_;
  std::vector<Root> roots_;
  std::vector<std::uint32_t> alive_;  // alive root indices, ascending (the only record of which live)
  std::vector<Outcome> outcome_;      // per-iteration slots (reused)
  int iteration_ = 0;
  double total_length_ = 0.0, longest_root_ = 0.0;
  std::size_t pending_seeds_ = 0;
  std::uint64_t climbing_nodes_ = 0, reflections_ = 0, floated_out_ = 0, collision_deaths_ = 0;
};

}  // namespace ivy
}  // namespace growbench
