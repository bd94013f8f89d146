// Hädrich, Benes, Deussen, Pirk 2017, "Interactive Modeling and Authoring of Climbing Plants": a plant
// is a tree of oriented particles that grow at the tips, turn toward surfaces and light, branch, carry
// leaves, collide with the scene's distance field, anchor where they touch, and bend (and break) under
// gravity and wind through oriented-particle shape matching.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "algorithms/algorithm.hpp"

namespace growbench {

namespace hadrich {

constexpr int kMaxChildren = 4;  // one successor + at most 3 laterals (max_laterals <= 3)

// A cut during the run: at `step`, the particles whose head lies within `radius` of `point` (radius 0:
// the one particle nearest to it) are removed with everything grown from them.
struct Cut {
  glm::vec3 point{0.0f};
  float radius = 0.0f;
  int step = 0;
};
// Parses "x,y,z,radius@step; ..." (the `prune` parameter). InputError naming the entry otherwise.
std::vector<Cut> parse_cuts(const std::string& text);

// The parameters in the units the simulation uses (angles in radians, the growth speed times its
// factor). Every value comes from the parameter table (make_setup): no member has a default of its own.
struct Config {
  // growth
  float particle_length;
  std::size_t max_particles;
  float growth_speed, shade_growth;
  float tip_radius, max_radius, thickening, radius_falloff;
  // tropisms (rates in 1/s, angles in radians)
  float adaptation, attraction_range, approach_angle;
  float phototropism;
  int light_rays;
  float light_spread, leaf_shadow, direction_noise, zone_rate;
  // branching and leaves
  int max_laterals, max_order, leaf_step;
  float shoot_density, branch_variance;
  float leaf_density, phyllotaxis, leaf_size, leaf_light;
  float flower_density, flower_size;
  // physics
  float dt, gravity, stiffness, damping;
  glm::vec3 start_velocity;  // added to the velocity each new particle inherits from its parent
  float surface_variability;
  int iterations;
  float friction, elasticity, anchor_pull, anchor_release;
  float break_sensitivity;
  glm::vec3 wind;
  float wind_strength, wind_gusts, gust_period;
};
// What the simulation reads from the parameters: the values, and the cuts the `prune` parameter asks for.
struct Setup {
  Config config;
  std::vector<Cut> cuts;
};
// InputError naming the parameter for a value that cannot work (a bad `prune` entry, wind without a direction).
Setup make_setup(const Params& params);

// The particle pool: a structure of arrays preallocated to max_particles, activated in order (a slot
// is never reused, so a parent always has a lower index than its children). A particle is an
// ellipsoid: semi-axis `half` along its forward axis (local +Z), `radius` across. It spans from its
// tail (x - half f) to its head (x + half f); a child's tail sits at its parent's head.
struct Particles {
  enum Flag : std::uint8_t {
    Active = 1,    // in the plant (not pruned)
    Growing = 2,   // a tip still lengthening
    Pinned = 4,    // a seed's first particle: its tail is fixed at the seed
    Anchored = 8,  // pulled toward `anchor`
    Touched = 16,  // touched a surface while growing: anchors when it matures
    Contact = 32,  // pushed out of a surface in the last step
  };
  std::vector<glm::vec3> x, v, w;  // centre, velocity, angular velocity
  std::vector<glm::quat> q;        // orientation (local +Z forward)
  std::vector<glm::quat> rest;     // rest orientation relative to the parent's frame
  std::vector<float> half, radius;
  std::vector<std::int32_t> parent;                              // -1: a seed's first particle, or broken off
  std::vector<std::array<std::int32_t, kMaxChildren>> children;  // -1: empty
  std::vector<std::uint32_t> shoot, birth, rank;                 // shoot id, step of birth, position along the shoot
  std::vector<std::uint16_t> order;
  std::vector<std::uint8_t> flags;
  std::vector<glm::vec3> anchor, normal;  // anchor point; last surface normal seen (zero: none near)
  std::vector<float> light;               // 1 - O at the last evaluation (tips)
  // Per-step scratch: predicted pose, shape-matching groups.
  std::vector<glm::vec3> xp, xp2, group_c, group_cbar;
  std::vector<glm::quat> qp, qp2, group_r;

  void reserve(std::size_t n);
  [[nodiscard]] std::size_t size() const { return x.size(); }
  [[nodiscard]] static std::size_t bytes_per_particle();
  [[nodiscard]] bool has(std::size_t i, Flag f) const { return (flags[i] & f) != 0; }
};

struct Leaf {
  std::int32_t particle = -1;
  float azimuth = 0.0f;  // around the particle's forward axis (phyllotaxis)
  float size = 0.0f;
};

// The simulation. step() = light, tropisms and growth at the tips, new particles, then one physics
// step for every particle. Deterministic for any thread count: parallel passes write only their own
// particle's slots, and new particles are created serially in index order.
class Simulator {
 public:
  Simulator(const Scene& scene, const SceneQuery& query, const Setup& setup, std::uint64_t seed);
  bool step();
  // Removes the particles whose head is within `radius` of `point` (radius 0: the nearest particle)
  // and their subtrees; returns how many were removed.
  std::size_t prune(const glm::vec3& point, float radius);
  // Removes particle i and everything grown from it.
  std::size_t prune_subtree(std::int32_t i);

  [[nodiscard]] const Plant& plant() const;
  [[nodiscard]] std::size_t node_count() const { return active_ + roots_; }
  [[nodiscard]] std::size_t leaf_count() const { return live_leaves_; }
  [[nodiscard]] const Particles& particles() const { return p_; }
  [[nodiscard]] std::vector<std::pair<std::string, double>> stats() const;
  [[nodiscard]] int steps() const { return step_; }
  // Particle index of each plant node (-1 for a root's base node at its tail).
  [[nodiscard]] const std::vector<std::int32_t>& node_particles() const {
    (void)plant();
    return node_particle_;
  }
  [[nodiscard]] glm::vec3 head(std::size_t i) const;
  [[nodiscard]] glm::vec3 forward(std::size_t i) const { return p_.q[i] * glm::vec3(0.0f, 0.0f, 1.0f); }

 private:
  std::int32_t activate(std::int32_t parent, const glm::vec3& tail, const glm::quat& q, std::uint32_t shoot,
                        std::uint16_t order, std::uint32_t rank, bool pinned);
  void add_seeds();
  void grow_tips();
  void spawn();
  void physics();
  void group_pass();
  void goal_pass();
  void contact_pass();
  void break_joints();
  [[nodiscard]] float occlusion(std::size_t i, const glm::vec3& at) const;
  [[nodiscard]] glm::vec3 wind(std::size_t i) const;
  [[nodiscard]] float max_radius(std::uint16_t order) const;
  [[nodiscard]] float surface_gap(std::size_t i) const;
  void build_leaf_grid();
  [[nodiscard]] std::uint64_t leaf_key(const glm::vec3& p) const;
  [[nodiscard]] float leaf_transmission(const glm::vec3& at) const;
  [[nodiscard]] Organ flower(const Leaf& fl, std::int32_t node) const;
  // A child's centre at rest, in its parent's frame: its tail on the parent's head.
  [[nodiscard]] glm::vec3 rest_offset(std::size_t parent, std::size_t child) const;

  const Scene& scene_;
  const SceneQuery& query_;
  Config cfg_;
  std::vector<Cut> cuts_;
  std::uint64_t seed_;
  glm::vec2 gap_offset_{0.0f};  // where this seed reads the surface-gap noise
  Particles p_;
  std::vector<Leaf> leaves_;
  std::vector<Leaf> flowers_;                           // azimuth: where its stalk leaves the stem; size: its diameter
  std::unordered_map<std::uint64_t, float> leaf_area_;  // leaf area density per cell (leaf_shadow), m^2/m^3
  float leaf_cell_ = 1.0f;                              // the side of a leaf_area_ cell
  std::vector<std::int32_t> tips_;                      // growing particles, ascending
  std::vector<std::uint8_t> seed_started_;
  int step_ = 0;
  std::size_t active_ = 0, roots_ = 0, live_leaves_ = 0;
  std::uint32_t next_shoot_ = 0;
  bool pool_full_ = false;
  std::uint64_t broken_ = 0, pruned_ = 0, anchors_made_ = 0;
  mutable Plant plant_;
  mutable std::vector<std::int32_t> node_particle_;
  mutable std::uint64_t plant_version_ = 0;
  std::uint64_t version_ = 0;  // bumped by every change (steps and prunes)
};

}  // namespace hadrich
}  // namespace growbench
