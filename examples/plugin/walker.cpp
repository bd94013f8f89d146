// walker: a random-walk climber, the growbench plugin SDK's example.
//
// Each growing tip takes one step per growth step: its heading, turned by a random wander and pulled
// towards the light, is laid into the surface's tangent plane; the host's closest-point query then
// snaps the new point onto the nearest climbable surface, `cling` away from it. A tip that finds no
// surface within `reach` moves freely for a few steps and dies if it does not find one. A move that
// would end inside a solid, or pass through one, is refused and the tip tries again with fresh random
// numbers. Now and then a tip starts a lateral branch. After the last step, radii follow the pipe
// model and leaves are placed along the shoots.
//
// It is written against the installed SDK only (growbench/plugin.hpp). Every step asks the host one
// batch per query for all tips at once. Random numbers come from the host's counter-based generator,
// keyed by the tip's node, so the plant depends on the seed alone, never on threads or call order.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <growbench/plugin.hpp>

namespace {

namespace sdk = growbench::sdk;
using sdk::Vec3;

Vec3 operator+(Vec3 a, Vec3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
Vec3 operator-(Vec3 a, Vec3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
Vec3 operator*(float s, Vec3 a) {
  return {s * a.x, s * a.y, s * a.z};
}
float dot(Vec3 a, Vec3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
float length(Vec3 a) {
  return std::sqrt(dot(a, a));
}
// `a` scaled to unit length, or `fallback` when `a` is (nearly) zero.
Vec3 normalized(Vec3 a, Vec3 fallback) {
  const float l = length(a);
  return l > 1e-12f ? (1.0f / l) * a : fallback;
}
// `v` with its component along the unit vector `n` removed.
Vec3 tangential(Vec3 v, Vec3 n) {
  return v - dot(v, n) * n;
}
// Rotates `v` about the unit axis `k` by `angle` radians (Rodrigues).
Vec3 rotated(Vec3 v, Vec3 k, float angle) {
  const float c = std::cos(angle), s = std::sin(angle);
  return c * v + s * cross(k, v) + (dot(k, v) * (1.0f - c)) * k;
}

// The unit quaternion (w, x, y, z) of the rotation whose columns are the orthonormal x, y, z.
void quaternion_from_frame(Vec3 x, Vec3 y, Vec3 z, float q[4]) {
  const float trace = x.x + y.y + z.z;
  if (trace > 0.0f) {
    const float s = 2.0f * std::sqrt(1.0f + trace);
    q[0] = 0.25f * s;
    q[1] = (y.z - z.y) / s;
    q[2] = (z.x - x.z) / s;
    q[3] = (x.y - y.x) / s;
  } else if (x.x > y.y && x.x > z.z) {
    const float s = 2.0f * std::sqrt(1.0f + x.x - y.y - z.z);
    q[0] = (y.z - z.y) / s;
    q[1] = 0.25f * s;
    q[2] = (y.x + x.y) / s;
    q[3] = (z.x + x.z) / s;
  } else if (y.y > z.z) {
    const float s = 2.0f * std::sqrt(1.0f + y.y - x.x - z.z);
    q[0] = (z.x - x.z) / s;
    q[1] = (y.x + x.y) / s;
    q[2] = 0.25f * s;
    q[3] = (z.y + y.z) / s;
  } else {
    const float s = 2.0f * std::sqrt(1.0f + z.z - x.x - y.y);
    q[0] = (x.y - y.x) / s;
    q[1] = (z.x + x.z) / s;
    q[2] = (z.y + y.z) / s;
    q[3] = 0.25f * s;
  }
}

constexpr double kPi = 3.14159265358979323846;

// Streams of the host's generator, one per use, so no two uses share a number.
enum Stream : std::uint64_t { kWanderZ = 1, kWanderPhi, kBranch, kBranchSide };

class Walker final : public sdk::Algorithm {
 public:
  static sdk::Info info() {
    return {"walker",
            "a random-walk climber: tips wander over the surfaces through batched closest-point queries, branch "
            "now and then, and stop at a node budget",
            "1.0",
            {
                sdk::real("step", 0.02).range(1e-4, 10).unit("m").doc("length of one move of a tip"),
                sdk::real("cling", 0.01).range(0, 1).unit("m").doc("distance a tip keeps from the surface it climbs"),
                sdk::real("reach", 0.1)
                    .range(1e-4, 100)
                    .unit("m")
                    .doc("a tip adheres to the nearest climbable surface within this distance"),
                sdk::integer("free_moves", 5)
                    .range(0, 1000)
                    .doc("moves a tip may make with no surface in reach before it dies"),
                sdk::real("wander", 0.6).range(0, 10).doc("weight of the random unit vector added to the heading"),
                sdk::real("light_pull", 0.4).range(0, 10).doc("weight of the direction towards the scene's light"),
                sdk::real("branch_chance", 0.04).range(0, 1).doc("chance per move that a tip starts a lateral branch"),
                sdk::real("branch_angle", 50).range(0, 180).unit("deg").doc("angle between a lateral and its parent"),
                sdk::integer("max_order", 4).range(0, 64).doc("laterals of this order start no further laterals"),
                sdk::integer("retries", 8).range(1, 1000).doc("refused moves in a row after which a tip dies"),
                sdk::integer("max_nodes", 20000).range(1, 50000000).doc("growth stops at this many nodes"),
                sdk::real("tip_radius", 0.002).range(1e-6, 10).unit("m").doc("radius of branch tips (pipe model)"),
                sdk::real("pipe_exponent", 2.5).range(1, 4).doc("pipe model exponent n: r^n = sum of children's r^n"),
                sdk::choice("leaves", "interval", {"none", "tips", "interval"})
                    .doc("where leaves go: none, at branch tips, or at tips and every leaf_interval nodes"),
                sdk::integer("leaf_interval", 6).range(1, 1000).doc("a leaf every k nodes along a shoot"),
                sdk::real("leaf_size", 0.04).range(0, 10).unit("m").doc("leaf blade length"),
                sdk::boolean("blossoms", true).doc("branch tips bear blossoms (the built-in shape), tinted by order"),
            },
            {"max_nodes=600"}};
  }

  void start(const sdk::Context& c) override {
    host_ = &c.host.table();
    scene_ = &c.scene;
    step_ = static_cast<float>(c.params.real("step"));
    cling_ = static_cast<float>(c.params.real("cling"));
    reach_ = static_cast<float>(c.params.real("reach"));
    free_moves_ = static_cast<int>(c.params.integer("free_moves"));
    wander_ = static_cast<float>(c.params.real("wander"));
    light_pull_ = static_cast<float>(c.params.real("light_pull"));
    branch_chance_ = c.params.real("branch_chance");
    branch_angle_ = static_cast<float>(c.params.real("branch_angle") * kPi / 180.0);
    max_order_ = static_cast<std::uint32_t>(c.params.integer("max_order"));
    retries_ = static_cast<int>(c.params.integer("retries"));
    max_nodes_ = static_cast<std::uint64_t>(c.params.integer("max_nodes"));
    tip_radius_ = static_cast<float>(c.params.real("tip_radius"));
    pipe_exponent_ = static_cast<float>(c.params.real("pipe_exponent"));
    leaves_ = c.params.text("leaves");
    leaf_interval_ = static_cast<std::uint32_t>(c.params.integer("leaf_interval"));
    leaf_size_ = static_cast<float>(c.params.real("leaf_size"));
    blossoms_ = c.params.boolean("blossoms");
    if (scene_->seed_count == 0) throw sdk::InputError("algorithm 'walker': the scene has no seeds");
    if (cling_ >= reach_) throw sdk::InputError("algorithm 'walker': cling must be less than reach");
  }

  bool step() override {
    plant_seeds();
    // With no tip growing, wait for the seeds still to start.
    if (tips_.empty()) return step_index_++ < last_start_step_;
    const std::size_t n = tips_.size();
    // One candidate per tip: its heading turned by the wander and the light, in the surface's plane.
    std::vector<Vec3> candidates(n);
    for (std::size_t i = 0; i < n; ++i) candidates[i] = propose(tips_[i]);
    std::vector<growbench_closest_hit> hits(n);
    host().closest_points(candidates.data(), n, hits.data(), reach_, true);
    std::vector<Vec3> normals(n);
    for (std::size_t i = 0; i < n; ++i) {
      normals[i] = tips_[i].normal;
      adhere(hits[i], candidates[i], normals[i]);
    }
    // Refuse moves that end inside a solid or cross one on the way.
    std::vector<std::uint8_t> inside(n), crossed(n);
    host().inside(candidates.data(), n, inside.data());
    std::vector<growbench_ray> segments(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 from = plant.nodes[static_cast<std::size_t>(tips_[i].node)].position;
      // t runs from the tip (0) to the candidate (1); a tiny tmin ignores a surface the tip rests on.
      segments[i] = {from, candidates[i] - from, 1e-3f, 1.0f};
    }
    host().occluded(segments.data(), n, crossed.data());

    std::vector<Tip> next;
    next.reserve(n);
    for (std::size_t i = 0; i < n && plant.nodes.size() < max_nodes_; ++i) {
      Tip t = tips_[i];
      if (inside[i] || crossed[i] || (!hits[i].found && t.free_left == 0)) {
        ++refused_;
        if (++t.attempt < retries_) next.push_back(t);
        continue;
      }
      grow(t, candidates[i], normals[i], hits[i].found != 0, next);
    }
    tips_ = std::move(next);
    ++step_index_;
    return (!tips_.empty() || step_index_ <= last_start_step_) && plant.nodes.size() < max_nodes_;
  }

  void finish() override {
    // Pipe model: children come after their parents, so one backward pass sums r^n into each parent.
    const float n = pipe_exponent_;
    std::vector<float> sum(plant.nodes.size(), 0.0f);
    for (std::size_t i = plant.nodes.size(); i-- > 0;) {
      growbench_node& node = plant.nodes[i];
      node.radius = sum[i] > 0.0f ? std::pow(sum[i], 1.0f / n) : tip_radius_;
      if (node.parent >= 0) sum[static_cast<std::size_t>(node.parent)] += std::pow(node.radius, n);
    }
    paint();
    if (leaves_ == "none" || leaf_size_ <= 0.0f) return;
    std::vector<std::uint8_t> has_child(plant.nodes.size(), 0);
    for (const growbench_node& node : plant.nodes)
      if (node.parent >= 0) has_child[static_cast<std::size_t>(node.parent)] = 1;
    for (std::size_t i = 0; i < plant.nodes.size(); ++i) {
      const growbench_node& node = plant.nodes[i];
      if (node.parent < 0) continue;
      const bool tip = has_child[i] == 0;
      const bool interval = leaves_ == "interval" && depth_[i] % leaf_interval_ == 0;
      if (tip || interval) add_leaf(i, tip && blossoms_);
    }
  }

  [[nodiscard]] std::vector<std::pair<std::string, double>> stats() const override {
    return {{"refused_moves", static_cast<double>(refused_)},
            {"free_moves", static_cast<double>(free_)},
            {"branches", static_cast<double>(branches_)},
            {"tips_alive", static_cast<double>(tips_.size())}};
  }

 private:
  struct Tip {
    std::int32_t node;  // the node it grows from
    Vec3 heading;       // unit
    Vec3 normal;        // unit, of the surface it last touched (the heading's plane)
    std::uint32_t order, shoot;
    std::uint32_t lane;  // 0: continues its shoot, 1: starts a lateral from `node`
    int attempt;         // refused moves in a row
    int free_left;       // moves left without a surface in reach
  };

  [[nodiscard]] sdk::Host host() const { return sdk::Host(host_); }

  // The counter of tip `t`'s random numbers: a function of the tip's node, lane and attempt only.
  static std::uint64_t counter(const Tip& t) {
    return (static_cast<std::uint64_t>(t.node) << 17) | (static_cast<std::uint64_t>(t.lane) << 16) |
           static_cast<std::uint64_t>(std::min(t.attempt, 0xffff));
  }

  // Starts one root per seed whose start step has come, snapped to the surface nearest to it (unless
  // that would put it inside a solid, as at a crease between two).
  void plant_seeds() {
    std::vector<const growbench_seed*> starting;
    for (std::uint32_t s = 0; s < scene_->seed_count; ++s) {
      const std::uint32_t start = static_cast<std::uint32_t>(std::max(scene_->seeds[s].start_step, 0));
      last_start_step_ = std::max(last_start_step_, start);
      if (start == step_index_) starting.push_back(&scene_->seeds[s]);
    }
    if (starting.empty()) return;
    const std::size_t n = starting.size();
    std::vector<Vec3> positions(n), normals(n, Vec3{0.0f, 1.0f, 0.0f});
    for (std::size_t i = 0; i < n; ++i) positions[i] = starting[i]->position;
    std::vector<growbench_closest_hit> hits(n);
    host().closest_points(positions.data(), n, hits.data(), reach_, true);
    for (std::size_t i = 0; i < n; ++i) adhere(hits[i], positions[i], normals[i]);
    std::vector<std::uint8_t> inside(n);
    host().inside(positions.data(), n, inside.data());
    for (std::size_t i = 0; i < n; ++i) {
      if (inside[i]) positions[i] = starting[i]->position;
      const Vec3 up{0.0f, 1.0f, 0.0f};
      const Vec3 heading = normalized(tangential(normalized(starting[i]->direction, up), normals[i]), up);
      const std::int32_t node = plant.add_node(positions[i], tip_radius_, -1, 0, next_shoot_, step_index_);
      depth_.push_back(0);
      normal_.push_back(normals[i]);
      tips_.push_back({node, heading, normals[i], 0, next_shoot_++, 0, 0, free_moves_});
    }
  }

  // The direction away from the surface at `hit`, on the side of `p`: a solid's outward normal, or an
  // open mesh's normal turned towards p.
  [[nodiscard]] Vec3 outward(const growbench_closest_hit& hit, Vec3 p) const {
    if (hit.mesh < scene_->mesh_count && scene_->meshes[hit.mesh].solid) return hit.normal;
    return dot(p - hit.point, hit.normal) < 0.0f ? -1.0f * hit.normal : hit.normal;
  }

  [[nodiscard]] Vec3 propose(const Tip& t) const {
    const std::uint64_t k = counter(t);
    const double z = 2.0 * host().uniform(kWanderZ, k) - 1.0;
    const double phi = 2.0 * kPi * host().uniform(kWanderPhi, k);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Vec3 random{static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)),
                      static_cast<float>(z)};
    const Vec3 from = plant.nodes[static_cast<std::size_t>(t.node)].position;
    const Vec3 light = scene_->light.point ? normalized(scene_->light.position - from, t.heading)
                                           : normalized(scene_->light.direction, t.heading);
    const Vec3 want = t.heading + wander_ * random + light_pull_ * light;
    return from + step_ * normalized(tangential(want, t.normal), t.heading);
  }

  // Moves `candidate` onto the surface `hit` found and sets `normal` to the surface's; with no surface
  // found, leaves both (a free move keeps the last normal).
  void adhere(const growbench_closest_hit& hit, Vec3& candidate, Vec3& normal) const {
    if (!hit.found) return;
    normal = outward(hit, candidate);
    candidate = hit.point + cling_ * normal;
  }

  // Appends the node of an accepted move and the tips that grow on from it.
  void grow(Tip t, Vec3 position, Vec3 normal, bool adhered, std::vector<Tip>& next) {
    const Vec3 from = plant.nodes[static_cast<std::size_t>(t.node)].position;
    const std::uint32_t depth = t.lane == 1 ? 1 : depth_[static_cast<std::size_t>(t.node)] + 1;
    const std::int32_t node = plant.add_node(position, tip_radius_, t.node, t.order, t.shoot, step_index_);
    depth_.push_back(depth);
    normal_.push_back(normal);
    if (!adhered) ++free_;
    Tip child = t;
    child.node = node;
    child.heading = normalized(position - from, t.heading);
    child.normal = normal;
    child.lane = 0;
    child.attempt = 0;
    child.free_left = adhered ? free_moves_ : t.free_left - 1;
    next.push_back(child);
    const std::uint64_t k = counter(child);
    if (t.order < max_order_ && host().uniform(kBranch, k) < branch_chance_) {
      const float side = host().uniform(kBranchSide, k) < 0.5 ? -1.0f : 1.0f;
      Tip lateral = child;
      lateral.heading = normalized(rotated(child.heading, normal, side * branch_angle_), child.heading);
      lateral.order = t.order + 1;
      lateral.shoot = next_shoot_++;
      lateral.lane = 1;
      next.push_back(lateral);
      ++branches_;
    }
  }

  // Per node, two named attributes that reach the PLY, glTF and skeleton files: "Cd", the branches' colour
  // (young green to old bark by the step a node appeared), and "shoot_depth", nodes from its shoot's start.
  // Each node's values depend on that node alone, so the host's parallel loop gives the same plant on any
  // number of threads.
  void paint() {
    const std::size_t n = plant.nodes.size();
    sdk::Attribute& color = plant.attribute("Cd", 3);  // references stay valid: attributes is a deque
    sdk::Attribute& depth = plant.attribute("shoot_depth", 1);
    color.values.resize(3 * n);
    depth.values.resize(n);
    const float last = static_cast<float>(std::max<std::uint32_t>(step_index_, 1));
    sdk::Host(host_).parallel_for(0, n, [&](std::uint64_t begin, std::uint64_t end) {
      for (std::uint64_t i = begin; i < end; ++i) {
        const float age = 1.0f - static_cast<float>(plant.nodes[i].birth_step) / last;  // 1: the oldest
        color.values[3 * i] = 0.16f + 0.10f * age;
        color.values[3 * i + 1] = 0.38f - 0.24f * age;
        color.values[3 * i + 2] = 0.08f;
        depth.values[i] = static_cast<float>(depth_[i]);
      }
    });
  }

  // A leaf at node i, its blade leaning out from the surface along the shoot, its upper side outwards; or,
  // at a tip, a blossom: the built-in shape, paler on higher orders.
  void add_leaf(std::size_t i, bool blossom) {
    const growbench_node& node = plant.nodes[i];
    const Vec3 from = plant.nodes[static_cast<std::size_t>(node.parent)].position;
    const Vec3 up{0.0f, 1.0f, 0.0f};
    const Vec3 along = normalized(node.position - from, up);
    const Vec3 out = normal_[i];
    const Vec3 z = normalized(along + out, along);
    const Vec3 y = normalized(tangential(out, z), normalized(tangential(up, z), {1.0f, 0.0f, 0.0f}));
    growbench_organ leaf{};
    leaf.position = node.position;
    quaternion_from_frame(cross(y, z), y, z, leaf.orientation);
    leaf.size = leaf_size_;
    leaf.kind = blossom ? GROWBENCH_ORGAN_FLOWER : GROWBENCH_ORGAN_LEAF;
    leaf.node = static_cast<std::int32_t>(i);
    if (!blossom) {
      plant.add_organ(leaf);
      return;
    }
    if (plant.organ_shapes.empty()) plant.organ_shapes = {"blossom"};
    const float pale = std::min(1.0f, 0.25f * static_cast<float>(node.order));
    plant.add_organ(leaf, 0, Vec3{1.0f, 0.7f + 0.3f * pale, 0.75f + 0.25f * pale});
  }

  const growbench_host* host_ = nullptr;
  const growbench_scene* scene_ = nullptr;
  float step_ = 0, cling_ = 0, reach_ = 0, wander_ = 0, light_pull_ = 0, branch_angle_ = 0;
  float tip_radius_ = 0, pipe_exponent_ = 0, leaf_size_ = 0;
  double branch_chance_ = 0;
  int free_moves_ = 0, retries_ = 0;
  std::uint32_t max_order_ = 0, leaf_interval_ = 1;
  std::uint64_t max_nodes_ = 0;
  std::string leaves_;
  bool blossoms_ = false;

  std::vector<Tip> tips_;
  // Per node: nodes from the start of its shoot, and the normal of the surface it clings to.
  std::vector<std::uint32_t> depth_;
  std::vector<Vec3> normal_;
  std::uint32_t step_index_ = 0, last_start_step_ = 0, next_shoot_ = 0;
  std::uint64_t refused_ = 0, free_ = 0, branches_ = 0;
};

}  // namespace

GROWBENCH_PLUGIN(Walker)
