// Hädrich et al. 2017 climbing plants (README.md beside this file).
//
// Where the paper gives no formula, the choice is written beside its parameter below and in the
// README. In short:
//  * Tropisms turn the growing tips only; a tip's rest orientation follows it while it grows, so the
//    plant's rest shape is the shape it grew into and the physics holds that shape (stiffness).
//  * Surface adaptation uses the paper's rotation (axis v_s x v_f, angle (v_s . v_f) tau dt), whose
//    fixed point is a tip parallel to the surface; to make a tip that is still approaching reach the
//    surface, the fixed point is tilted toward it by an approach angle that falls linearly from
//    `approach_angle` at the edge of the attraction range to 0 at contact (approach_angle 0 is the
//    paper's rule exactly). v_s comes from the closest point on a climbable mesh (Embree, bounded by
//    the attraction range), so the ground, which is not climbable, does not capture the shoots.
//  * Phototropism turns toward the light: rotated about v_f x v_l (with the restated axis v_l x v_f a
//    positive angle would turn away from it) by (1 - O) eta dt, never past the light direction.
//    O is the fraction of `light_rays` rays in a cone toward the light that the scene blocks; with
//    leaf_shadow, the light the plant's own leaves let through (a leaf density grid) multiplies 1 - O.
//  * Growth rate: growth_speed x (shade_growth + (1 - shade_growth)(1 - O)).
//  * Anchors: a tip that touches a surface while growing anchors where it is when it matures (a
//    growing tip moves forward, so an anchor on it would hold it back); released past anchor_release.
//  * Occlusion and surface queries run for tips only; every particle gets a distance-field collision
//    test each step (one read of eight voxels).
#include "algorithms/hadrich/hadrich.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <sstream>

#include <fmt/format.h>
#define GLM_ENABLE_EXPERIMENTAL  // glm::rotation (shortest arc between two vectors)
#include <glm/gtc/noise.hpp>
#include <glm/gtx/quaternion.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/errors.hpp"
#include "core/random.hpp"

namespace growbench {
namespace {

constexpr float kDeg = std::numbers::pi_v<float> / 180.0f;

// ---- parameter table (what `growbench list` prints) ----
const AlgorithmInfo kInfo = {
    .name = "hadrich",
    .summary =
        "Hädrich et al. 2017 climbing plants: oriented particles grow at the tips, adapt to surfaces, seek light, "
        "branch (Leeuwenberg), carry leaves, anchor, collide with the distance field and bend under shape matching",
    .params =
        {
            // growth
            param::real("particle_length", 0.02)
                .range(1e-4, 10)
                .unit("m")
                .doc("length of a grown particle (one plant segment)"),
            param::integer("max_particles", 10000)
                .range(1, 20000000)
                .doc("the preallocated pool; growth ends when it is full"),
            param::real("growth_speed", 0.2).range(0, 100).unit("m/s").doc("tip extension speed in full light"),
            param::real("growth_factor", 1.0).range(0, 100).doc("user factor on the growth speed"),
            param::real("shade_growth", 0.25)
                .range(0, 1)
                .doc("growth in full shade as a fraction of full-light growth: speed x (this + (1 - this)(1 - O)) (the "
                     "paper scales growth with light but gives no formula)"),
            param::real("tip_radius", 0.002).range(1e-6, 10).unit("m").doc("radius of a new main-axis particle"),
            param::real("max_radius", 0.012).range(1e-6, 10).unit("m").doc("radius a main-axis particle thickens to"),
            param::real("thickening", 0.002)
                .range(0, 10)
                .unit("m/s")
                .doc("secondary growth: radius gained per second by grown particles"),
            param::real("radius_falloff", 0.7)
                .range(0.01, 1)
                .doc("a lateral branch's radii are its parent's times this"),
            // tropisms
            param::real("adaptation", 6.0)
                .range(0, 1000)
                .unit("1/s")
                .doc(
                    "tau: surface adaptation, angle (v_s . v_f - sin(approach)) tau dt about v_s x v_f (the seed's tau "
                    "in [0, 1] turns too slowly at dt = 25 ms; a rate here)"),
            param::real("attraction_range", 0.15)
                .range(0, 100)
                .unit("m")
                .doc("surfaces farther than this from a tip do not attract it"),
            param::real("approach_angle", 75.0)
                .range(0, 90)
                .unit("deg")
                .doc("a tip in range turns to meet the surface at this angle, falling linearly to 0 (parallel) at "
                     "contact; 0: the paper's rule, which only aligns tips with surfaces"),
            param::real("phototropism", 1.5)
                .range(0, 1000)
                .unit("1/s")
                .doc("eta: turn toward the light by (1 - O) eta dt"),
            param::integer("light_rays", 4).range(0, 256).doc("rays per tip to estimate occlusion O (0: O = 0)"),
            param::real("leaf_shadow", 0.0)
                .range(0, 10)
                .doc("how much the plant's own leaves shade its tips (the paper's shadow map counted them): light "
                     "through the leaves falls as exp(-0.5 x this x leaf area density x path), Beer-Lambert for "
                     "randomly turned leaves at 1; 0: only the scene shades"),
            param::real("light_spread", 5.0)
                .range(0, 60)
                .unit("deg")
                .doc("half-angle of the cone of light rays (soft shadows)"),
            param::real("direction_noise", 6.0)
                .range(0, 90)
                .unit("deg")
                .doc("random turn of each new particle (at most)"),
            param::real("zone_rate", 3.0)
                .range(0, 1000)
                .unit("1/s")
                .doc("a tip in an attract (repel) zone turns toward (away from) its centre by strength x this x dt"),
            // branching and leaves
            param::integer("max_laterals", 1).range(0, 3).doc("B: lateral buds per particle (Leeuwenberg)"),
            param::real("shoot_density", 0.08).range(0, 1).doc("BP: probability that each lateral bud grows a shoot"),
            param::real("branch_variance", 0.8)
                .range(0, 1)
                .doc("V: a lateral leaves its parent at V x 90 deg (minus up to 30% at random)"),
            param::integer("max_order", 3).range(0, 100).doc("shoots of this branch order grow no laterals"),
            param::real("leaf_density", 0.7).range(0, 1).doc("probability of a leaf at each leaf_step-th particle"),
            param::integer("leaf_step", 1).range(1, 1000).doc("phyllotaxis step: particles between leaf sites"),
            param::real("phyllotaxis", 137.5)
                .range(0, 360)
                .unit("deg")
                .doc("turn between successive leaf sites of a shoot"),
            param::real("leaf_size", 0.05).range(0, 10).unit("m").doc("leaf blade length"),
            param::real("leaf_light", 0.7)
                .range(0, 1)
                .doc("how far a leaf turns its upper side from its phyllotactic pose to face the light"),
            param::real("flower_density", 0.0)
                .range(0, 1)
                .doc("probability of a flower at each phyllotaxis site, opposite its leaf, facing the light"),
            param::real("flower_size", 0.04).range(0, 10).unit("m").doc("flower diameter"),
            // physics
            param::real("dt", 0.025).range(1e-4, 1).unit("s").doc("time step (the paper: 25 ms)"),
            param::real("gravity", 0.5)
                .range(0, 1000)
                .unit("m/s^2")
                .doc("a_g, the downward acceleration of free particles (below Earth's: growth runs in time-lapse)"),
            param::vec3("start_velocity", glm::dvec3(0.0))
                .range(-100, 100)
                .unit("m/s")
                .doc("velocity every new particle is born with, added to its parent's (the Houdini tool's "
                     "starting velocity)"),
            param::real("surface_variability", 0.0)
                .range(0, 1)
                .unit("m")
                .doc("each particle keeps up to this much farther from surfaces than its thickness, drawn per "
                     "particle, so shoots do not hug the surface as closely (the Houdini tool's variability from "
                     "surface). It is capped at the distance field's narrow band, where the push-out acts: widen the "
                     "band (--band-voxels) for more"),
            param::real("stiffness", 0.8)
                .range(0, 1)
                .doc("shape matching: fraction of the way to the goal per iteration"),
            param::integer("iterations", 2).range(1, 100).doc("shape-matching iterations per step"),
            param::real("damping", 0.05).range(0, 1).doc("fraction of linear and angular velocity removed per step"),
            param::real("friction", 0.6).range(0, 1).doc("tangential velocity removed at a contact"),
            param::real("elasticity", 0.1).range(0, 1).doc("normal velocity reflected at a contact"),
            param::real("anchor_pull", 0.5).range(0, 1).doc("phi: x += phi (anchor - x) per step"),
            param::real("anchor_release", 0.03)
                .range(0, 100)
                .unit("m")
                .doc("an anchor lets go when its particle is this far from it"),
            param::real("break_sensitivity", 0.0)
                .range(0, 1e6)
                .doc("a joint breaks when its gap exceeds particle_length / this; 0: never"),
            param::vec3("wind", glm::dvec3(1.0, 0.0, 0.0)).range(-1e3, 1e3).doc("wind direction"),
            param::real("wind_strength", 0.0).range(0, 1e4).unit("m/s^2").doc("wind acceleration a_e"),
            param::real("wind_gusts", 0.5)
                .range(0, 10)
                .doc("gust amplitude relative to the strength (smooth counter-based noise per shoot)"),
            param::real("gust_period", 1.5).range(1e-3, 1e3).unit("s").doc("time between gust peaks"),
            param::text("prune").doc(
                "cuts during the run, 'x,y,z,radius@step; ...': at that step the particles whose head is within "
                "radius of the point (radius 0: the nearest one) and all they grew are removed"),
        },
    .test_params = {"max_particles=2000"},
};

constexpr std::uint64_t kNoiseStream = 0x4ad71c00ull << 32;
constexpr std::uint64_t kBranchStream = 0x4ad7b400ull << 32;
constexpr std::uint64_t kLeafStream = 0x4ad71e00ull << 32;
constexpr std::uint64_t kGapStream = 0x4ad79a00ull << 32;
constexpr float kLeafShadowCells = 64.0f;
constexpr float kBandUse = 0.9f;  // the share of the distance field's band surface_variability may use  // how far
                                  // toward the light the leaf shade is summed, in cells
constexpr std::uint64_t kLightStream = 0x4ad7119bull << 32;
constexpr std::uint64_t kWindStream = 0x4ad7714dull << 32;
constexpr glm::vec3 kZ{0.0f, 0.0f, 1.0f};
constexpr std::size_t kGrain = 512;

// Rotation taking unit vector a toward unit vector b by `angle` (clamped to the angle between them).
glm::quat turn_toward(const glm::vec3& a, const glm::vec3& b, float angle) {
  const glm::vec3 axis = glm::cross(a, b);
  const float s = glm::length(axis);
  if (s < 1e-7f) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  const float between = std::atan2(s, glm::dot(a, b));
  return glm::angleAxis(std::clamp(angle, -between, between), axis / s);
}

// A unit vector perpendicular to unit f.
glm::vec3 any_perpendicular(const glm::vec3& f) {
  const glm::vec3 t = std::abs(f.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  return glm::normalize(glm::cross(f, t));
}

// Rotation part of A (columns), by the iteration of Müller et al. 2016 ("A robust method to extract
// the rotational part of deformations"), warm-started at q (the group owner's predicted orientation,
// which is within a small angle of the answer, so a few iterations suffice). Each update turns by
// omega; the quaternion (1, omega / 2) normalised is that turn to second order in |omega|, without a
// sine and cosine, and the iteration corrects what it misses.
glm::quat extract_rotation(const glm::mat3& A, glm::quat q) {
  for (int it = 0; it < 4; ++it) {
    const glm::mat3 R = glm::mat3_cast(q);
    const glm::vec3 num = glm::cross(R[0], A[0]) + glm::cross(R[1], A[1]) + glm::cross(R[2], A[2]);
    const float den = std::abs(glm::dot(R[0], A[0]) + glm::dot(R[1], A[1]) + glm::dot(R[2], A[2])) + 1e-20f;
    const glm::vec3 half = num * (0.5f / den);
    if (glm::dot(half, half) < 1e-10f) break;  // below 2e-5 rad
    q = glm::normalize(glm::quat(1.0f, half.x, half.y, half.z) * q);
  }
  return q;
}

class HadrichAlgorithm final : public GrowthAlgorithm {
 public:
  const AlgorithmInfo& describe() const override { return kInfo; }
  void start(const Scene& scene, const SceneQuery& query, const Params& params, std::uint64_t seed) override {
    if (!query.has_sdf()) throw InputError("hadrich: the scene query has no distance field (collision needs one)");
    sim_ = std::make_unique<hadrich::Simulator>(scene, query, hadrich::make_setup(params), seed);
    not_applicable_ = scene.has_climbable() ? ""
                                            : fmt::format(
                                                  "nothing to climb: scene '{}' has no climbable surface, "
                                                  "and a climbing plant without support lies on the ground",
                                                  scene.name);
  }
  OwnVerdict own_verdict() const override { return {not_applicable_, {}}; }
  bool step() override { return sim_->step(); }
  const Plant& plant() const override { return sim_ ? sim_->plant() : empty_; }
  std::size_t node_count() const override { return sim_ ? sim_->node_count() : 0; }
  std::size_t organ_count() const override { return sim_ ? sim_->leaf_count() : 0; }
  std::vector<std::pair<std::string, double>> stats() const override { return sim_->stats(); }

 private:
  std::unique_ptr<hadrich::Simulator> sim_;
  std::string not_applicable_;
  Plant empty_;
};

}  // namespace

GROWBENCH_REGISTER_ALGORITHM(hadrich, HadrichAlgorithm, kInfo, hadrich::Config)

namespace hadrich {

std::vector<Cut> parse_cuts(const std::string& text) {
  std::vector<Cut> cuts;
  std::stringstream all(text);
  std::string entry;
  int n = 0;
  while (std::getline(all, entry, ';')) {
    ++n;
    if (entry.find_first_not_of(" \t") == std::string::npos) continue;
    auto bad = [&](const std::string& why) {
      return InputError(
          fmt::format("hadrich: parameter 'prune', entry {} '{}': {}; expected 'x,y,z,radius@step'", n, entry, why));
    };
    const auto at = entry.find('@');
    if (at == std::string::npos) throw bad("no '@step'");
    float v[4];
    std::stringstream nums(entry.substr(0, at));
    std::string item;
    int k = 0;
    while (std::getline(nums, item, ',')) {
      if (k == 4) throw bad("more than four numbers before '@'");
      const auto b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
      if (b == std::string::npos) throw bad("an empty number");
      const char* first = item.data() + b;
      const char* last = item.data() + e + 1;
      const auto r = std::from_chars(first, last, v[k]);
      if (r.ec != std::errc() || r.ptr != last || !std::isfinite(v[k]))
        throw bad(fmt::format("'{}' is not a number", item));
      ++k;
    }
    if (k != 4) throw bad(fmt::format("{} numbers before '@'", k));
    if (v[3] < 0.0f) throw bad("a negative radius");
    std::string step = entry.substr(at + 1);
    step.erase(0, step.find_first_not_of(" \t"));
    step.erase(step.find_last_not_of(" \t") + 1);
    int s = 0;
    const auto r = std::from_chars(step.data(), step.data() + step.size(), s);
    if (r.ec != std::errc() || r.ptr != step.data() + step.size() || s < 0)
      throw bad(fmt::format("step '{}' is not a non-negative integer", step));
    cuts.push_back({{v[0], v[1], v[2]}, v[3], s});
  }
  return cuts;
}

Setup make_setup(const Params& p) {
  auto f = [&](const char* k) { return static_cast<float>(p.real(k)); };
  auto i = [&](const char* k) { return static_cast<int>(p.integer(k)); };
  const glm::vec3 w(p.vec3("wind"));
  if (glm::length(w) < 1e-12f && p.real("wind_strength") > 0.0)
    throw InputError("hadrich: parameter 'wind' is the zero vector but wind_strength > 0; expected a direction");
  // Designated initializers: a member left out is a warning (-Wmissing-field-initializers), an error in CI.
  const Config c = {
      .particle_length = f("particle_length"),
      .max_particles = static_cast<std::size_t>(p.integer("max_particles")),
      .growth_speed = f("growth_speed") * f("growth_factor"),
      .shade_growth = f("shade_growth"),
      .tip_radius = f("tip_radius"),
      .max_radius = std::max(f("max_radius"), f("tip_radius")),
      .thickening = f("thickening"),
      .radius_falloff = f("radius_falloff"),
      .adaptation = f("adaptation"),
      .attraction_range = f("attraction_range"),
      .approach_angle = f("approach_angle") * kDeg,
      .phototropism = f("phototropism"),
      .light_rays = i("light_rays"),
      .light_spread = f("light_spread") * kDeg,
      .leaf_shadow = f("leaf_shadow"),
      .direction_noise = f("direction_noise") * kDeg,
      .zone_rate = f("zone_rate"),
      .max_laterals = i("max_laterals"),
      .max_order = i("max_order"),
      .leaf_step = i("leaf_step"),
      .shoot_density = f("shoot_density"),
      .branch_variance = f("branch_variance"),
      .leaf_density = f("leaf_density"),
      .phyllotaxis = f("phyllotaxis") * kDeg,
      .leaf_size = f("leaf_size"),
      .leaf_light = f("leaf_light"),
      .flower_density = f("flower_density"),
      .flower_size = f("flower_size"),
      .dt = f("dt"),
      .gravity = f("gravity"),
      .stiffness = f("stiffness"),
      .damping = f("damping"),
      .start_velocity = glm::vec3(p.vec3("start_velocity")),
      .surface_variability = f("surface_variability"),
      .iterations = i("iterations"),
      .friction = f("friction"),
      .elasticity = f("elasticity"),
      .anchor_pull = f("anchor_pull"),
      .anchor_release = f("anchor_release"),
      .break_sensitivity = f("break_sensitivity"),
      .wind = glm::length(w) > 0.0f ? glm::normalize(w) : w,
      .wind_strength = f("wind_strength"),
      .wind_gusts = f("wind_gusts"),
      .gust_period = f("gust_period"),
  };
  return {c, parse_cuts(p.text("prune"))};
}

// ---- particles ----

void Particles::reserve(std::size_t n) {
  auto r = [n](auto&... v) { (v.reserve(n), ...); };
  r(x, v, w, q, rest, half, radius, parent, children, shoot, birth, rank, order, flags, anchor, normal, light, xp, xp2,
    group_c, group_cbar, qp, qp2, group_r);
}

std::size_t Particles::bytes_per_particle() {
  return 3 * sizeof(glm::vec3) + 2 * sizeof(glm::quat) + 2 * sizeof(float) + sizeof(std::int32_t) +
         sizeof(std::array<std::int32_t, kMaxChildren>) + 3 * sizeof(std::uint32_t) + sizeof(std::uint16_t) +
         sizeof(std::uint8_t) + 2 * sizeof(glm::vec3) + sizeof(float) +  // state
         4 * sizeof(glm::vec3) + 3 * sizeof(glm::quat);                  // scratch
}

// ---- simulator ----

Simulator::Simulator(const Scene& scene, const SceneQuery& query, const Setup& setup, std::uint64_t seed)
    : scene_(scene), query_(query), cfg_(setup.config), cuts_(setup.cuts), seed_(seed) {
  Rng gap(seed, kGapStream, 0);  // each seed reads its own part of the surface-gap noise
  gap_offset_ = glm::vec2(gap.uniform(0.0, 256.0), gap.uniform(0.0, 256.0));
  p_.reserve(cfg_.max_particles);
  seed_started_.assign(scene_.seeds.size(), 0);
  if (scene_.seeds.empty()) throw InputError(fmt::format("hadrich: scene '{}' has no seeds", scene_.name));
  add_seeds();
}

float Simulator::max_radius(std::uint16_t order) const {
  return cfg_.max_radius * std::pow(cfg_.radius_falloff, static_cast<float>(order));
}

glm::vec3 Simulator::rest_offset(std::size_t parent, std::size_t child) const {
  return glm::vec3(0, 0, p_.half[parent]) + p_.rest[child] * glm::vec3(0, 0, p_.half[child]);
}

glm::vec3 Simulator::head(std::size_t i) const {
  return p_.x[i] + forward(i) * p_.half[i];
}

std::int32_t Simulator::activate(std::int32_t parent, const glm::vec3& tail, const glm::quat& q, std::uint32_t shoot,
                                 std::uint16_t order, std::uint32_t rank, bool pinned) {
  if (p_.size() >= cfg_.max_particles) {
    pool_full_ = true;
    return -1;
  }
  const auto i = static_cast<std::int32_t>(p_.size());
  const float h = 0.05f * cfg_.particle_length;  // a new particle starts at a tenth of its length
  const glm::vec3 f = q * kZ;
  p_.x.push_back(tail + f * h);
  p_.v.push_back((parent >= 0 ? p_.v[parent] : glm::vec3(0.0f)) + cfg_.start_velocity);
  p_.w.push_back(glm::vec3(0.0f));
  p_.q.push_back(q);
  p_.rest.push_back(parent >= 0 ? glm::conjugate(p_.q[parent]) * q : glm::quat(1, 0, 0, 0));
  p_.half.push_back(h);
  p_.radius.push_back(cfg_.tip_radius * std::pow(cfg_.radius_falloff, static_cast<float>(order)));
  p_.parent.push_back(parent);
  p_.children.push_back({-1, -1, -1, -1});
  p_.shoot.push_back(shoot);
  p_.birth.push_back(static_cast<std::uint32_t>(step_));
  p_.rank.push_back(rank);
  p_.order.push_back(order);
  p_.flags.push_back(
      static_cast<std::uint8_t>(Particles::Active | Particles::Growing | (pinned ? Particles::Pinned : 0)));
  p_.anchor.push_back(glm::vec3(0.0f));
  p_.normal.push_back(parent >= 0 ? p_.normal[parent] : glm::vec3(0.0f));
  p_.light.push_back(parent >= 0 ? p_.light[parent] : 1.0f);
  p_.xp.push_back(p_.x.back());
  p_.xp2.push_back(p_.x.back());
  p_.qp.push_back(q);
  p_.qp2.push_back(q);
  p_.group_c.emplace_back(0.0f);
  p_.group_cbar.emplace_back(0.0f);
  p_.group_r.emplace_back(1, 0, 0, 0);
  if (parent >= 0) {
    auto& ch = p_.children[parent];
    *std::find(ch.begin(), ch.end(), -1) = i;  // the caller checked there is room
  } else {
    ++roots_;
  }
  ++active_;
  tips_.push_back(i);
  return i;
}

void Simulator::add_seeds() {
  for (std::size_t s = 0; s < scene_.seeds.size(); ++s) {
    const Seed& seed = scene_.seeds[s];
    if (seed_started_[s] || seed.start_step > step_) continue;
    seed_started_[s] = 1;
    const glm::vec3 d = glm::length(seed.direction) > 0.0f ? glm::normalize(seed.direction) : glm::vec3(0, 1, 0);
    if (activate(-1, seed.position, glm::rotation(kZ, d), next_shoot_, 0, 0, true) >= 0) ++next_shoot_;
    ++version_;
  }
}

float Simulator::occlusion(std::size_t i, const glm::vec3& at) const {
  if (cfg_.light_rays <= 0) return 0.0f;
  const Light& light = scene_.light;
  const glm::vec3 l = light.towards(at);
  const float dist = light.distance(at);
  const glm::vec3 u = any_perpendicular(l), v = glm::cross(l, u);
  const float spread = std::tan(cfg_.light_spread);
  // A fixed spiral of directions in the cone, turned by a per-particle angle: smooth penumbrae and no
  // per-step noise.
  const auto phase = static_cast<float>(Rng(seed_, kLightStream, i).uniform() * 2.0 * std::numbers::pi);
  int blocked = 0;
  for (int k = 0; k < cfg_.light_rays; ++k) {
    const float r = cfg_.light_rays == 1
                        ? 0.0f
                        : spread * std::sqrt((static_cast<float>(k) + 0.5f) / static_cast<float>(cfg_.light_rays));
    const float a = phase + 2.39996323f * static_cast<float>(k);
    const glm::vec3 d = glm::normalize(l + r * (std::cos(a) * u + std::sin(a) * v));
    if (query_.occluded(at, d, dist, 1e-3f)) ++blocked;
  }
  return static_cast<float>(blocked) / static_cast<float>(cfg_.light_rays);
}

// The leaf area density grid for leaf_shadow, rebuilt each step from the leaves in order (a fixed sum
// order: the same grid for any thread count). A cell is twice the leaf size, so a leaf lies in about one.
void Simulator::build_leaf_grid() {
  leaf_area_.clear();
  leaf_cell_ = std::max(2.0f * cfg_.leaf_size, 1e-3f);
  const float volume = leaf_cell_ * leaf_cell_ * leaf_cell_;
  for (const Leaf& l : leaves_) {
    const auto i = static_cast<std::size_t>(l.particle);
    leaf_area_[leaf_key(p_.x[i] + forward(i) * p_.half[i])] += 0.5f * l.size * l.size / volume;
  }
}

std::uint64_t Simulator::leaf_key(const glm::vec3& p) const {
  const glm::ivec3 c = glm::ivec3(glm::floor(p / leaf_cell_)) + glm::ivec3(1 << 20);
  return (static_cast<std::uint64_t>(c.x & 0x1FFFFF) << 42) | (static_cast<std::uint64_t>(c.y & 0x1FFFFF) << 21) |
         static_cast<std::uint64_t>(c.z & 0x1FFFFF);
}

// The share of light the plant's own leaves let through to `at`: a march toward the light through the
// leaf grid, from the next cell on (a tip's own leaf does not shade it), up to kLeafShadowCells cells.
float Simulator::leaf_transmission(const glm::vec3& at) const {
  if (cfg_.leaf_shadow <= 0.0f || leaf_area_.empty()) return 1.0f;
  const glm::vec3 l = scene_.light.towards(at);
  const float reach = std::min(scene_.light.distance(at), kLeafShadowCells * leaf_cell_);
  float depth = 0.0f;
  for (float s = leaf_cell_; s < reach; s += 0.5f * leaf_cell_)
    if (const auto it = leaf_area_.find(leaf_key(at + s * l)); it != leaf_area_.end())
      depth += it->second * 0.5f * leaf_cell_;
  return std::exp(-0.5f * cfg_.leaf_shadow * depth);
}

glm::vec3 Simulator::wind(std::size_t i) const {
  if (cfg_.wind_strength <= 0.0f) return glm::vec3(0.0f);
  // Smooth value noise in time, one sequence per shoot, from counter-based random values.
  const double t = static_cast<double>(step_) * cfg_.dt / cfg_.gust_period;
  const auto k = static_cast<std::uint64_t>(std::floor(t));
  const auto fr = static_cast<float>(t - std::floor(t));
  auto value = [&](std::uint64_t n) {
    return static_cast<float>(random_bits(seed_, kWindStream ^ p_.shoot[i], n) >> 11) * 0x1.0p-53f * 2.0f - 1.0f;
  };
  const float s = fr * fr * (3.0f - 2.0f * fr);
  const float noise = value(k) + (value(k + 1) - value(k)) * s;
  return cfg_.wind * (cfg_.wind_strength * (1.0f + cfg_.wind_gusts * noise));
}

// Light, tropisms and growth of every tip, in parallel (each tip writes only its own slots).
void Simulator::grow_tips() {
  const float dt = cfg_.dt;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tips_.size(), 64), [&](const auto& range) {
    for (std::size_t t = range.begin(); t != range.end(); ++t) {
      const auto i = static_cast<std::size_t>(tips_[t]);
      const glm::vec3 f = forward(i);
      const glm::vec3 tail = p_.x[i] - f * p_.half[i];
      const glm::vec3 tip = tail + f * p_.half[i] * 2.0f;
      glm::quat turn(1, 0, 0, 0);
      float near = 0.0f;  // 1 at a surface, 0 at the attraction range and beyond
      // Surface adaptation toward the nearest climbable surface within range.
      if (cfg_.adaptation > 0.0f && cfg_.attraction_range > 0.0f) {
        const ClosestHit c = query_.closest_point(tip, cfg_.attraction_range, true);
        if (c.found) {
          glm::vec3 vs = c.point - tip;
          const float d = glm::length(vs);
          vs = d > 1e-7f ? vs / d : -c.normal;
          // The approach angle falls to 0 at the surface itself, so an approaching tip keeps a slight
          // pull until the collision test stops it there (and it touches).
          const float reach = std::clamp(2.0f * d / cfg_.attraction_range, 0.0f, 1.0f);
          const float target = std::sin(cfg_.approach_angle * reach);  // cos of the wanted angle to v_s
          const float angle = (glm::dot(vs, f) - target) * cfg_.adaptation * dt;
          glm::vec3 axis = glm::cross(vs, f);
          const float s = glm::length(axis);
          axis = s > 1e-6f ? axis / s : any_perpendicular(f);
          turn = glm::angleAxis(angle, axis);
          p_.normal[i] = -vs;
          near = std::clamp(2.0f - 2.0f * d / cfg_.attraction_range, 0.0f, 1.0f);
        } else {
          p_.normal[i] = glm::vec3(0.0f);
        }
      }
      // Phototropism. Near a surface the tip seeks the light along it: the target keeps the tip's own
      // angle to the surface and takes the light's direction within the surface's tangent plane (a
      // climber does not peel off its support toward the sun; adaptation alone decides how it meets
      // the surface). Blended in over the outer half of the attraction range.
      const float lit = (1.0f - occlusion(i, tip)) * leaf_transmission(tip);
      p_.light[i] = lit;
      if (cfg_.phototropism > 0.0f) {
        const glm::vec3 f1 = turn * f;
        glm::vec3 l = scene_.light.towards(tip);
        if (near > 0.0f) {
          const glm::vec3 ns = p_.normal[i];
          const glm::vec3 along = l - glm::dot(l, ns) * ns;
          const float fn = glm::dot(f1, ns);
          if (glm::length(along) > 1e-4f) {
            const glm::vec3 kept = glm::normalize(along) * std::sqrt(std::max(0.0f, 1.0f - fn * fn)) + fn * ns;
            l = glm::normalize(glm::mix(l, kept, near));
          }
        }
        turn = turn_toward(f1, l, lit * cfg_.phototropism * dt) * turn;
      }
      // Painted attractors and repulsors.
      for (const Zone& z : scene_.zones) {
        if (z.kind != Zone::Kind::Attract && z.kind != Zone::Kind::Repel) continue;
        if (!query_.inside_shape(z.shape, tip)) continue;
        const glm::vec3 centre = z.shape.kind == Shape::Kind::Sphere ? z.shape.center : z.shape.bounds().center();
        glm::vec3 to = centre - tip;
        if (glm::length(to) < 1e-7f) continue;
        to = glm::normalize(z.kind == Zone::Kind::Attract ? to : -to);
        turn = turn_toward(turn * f, to, z.strength * cfg_.zone_rate * dt) * turn;
      }
      const glm::quat q = glm::normalize(turn * p_.q[i]);
      const float speed = cfg_.growth_speed * (cfg_.shade_growth + (1.0f - cfg_.shade_growth) * lit);
      const float h = std::min(0.5f * cfg_.particle_length, p_.half[i] + 0.5f * speed * dt);
      p_.q[i] = q;
      p_.half[i] = h;
      p_.x[i] = tail + (q * kZ) * h;
      if (p_.parent[i] >= 0) p_.rest[i] = glm::conjugate(p_.q[p_.parent[i]]) * q;
    }
  });
}

// New particles at matured tips, serially in tip order (so indices do not depend on threads).
void Simulator::spawn() {
  std::vector<std::int32_t> next;
  next.reserve(tips_.size() + 8);
  const std::size_t before = tips_.size();
  for (std::size_t t = 0; t < before; ++t) {
    const std::int32_t i = tips_[t];
    if (!p_.has(i, Particles::Active) || !p_.has(i, Particles::Growing)) continue;
    if (p_.half[i] < 0.5f * cfg_.particle_length * (1.0f - 1e-6f)) {
      next.push_back(i);
      continue;
    }
    p_.flags[i] &= static_cast<std::uint8_t>(~Particles::Growing);
    if (p_.has(i, Particles::Touched) && !p_.has(i, Particles::Pinned)) {
      p_.flags[i] |= Particles::Anchored;
      p_.anchor[i] = p_.x[i];
      ++anchors_made_;
    }
    // Exclude zones end a shoot; include zones end shoots that leave them.
    const glm::vec3 h = head(i);
    bool stop = false, any_include = false, in_include = false;
    for (const Zone& z : scene_.zones) {
      if (z.kind == Zone::Kind::Exclude && query_.inside_shape(z.shape, h)) stop = true;
      if (z.kind == Zone::Kind::Include) {
        any_include = true;
        in_include = in_include || query_.inside_shape(z.shape, h);
      }
    }
    if (stop || (any_include && !in_include)) continue;
    const auto idx = static_cast<std::uint64_t>(i);
    Rng rng(seed_, kNoiseStream, idx * 16);
    // The successor: the same direction, turned at random by up to direction_noise.
    const glm::vec3 f = forward(static_cast<std::size_t>(i));
    const float noise = cfg_.direction_noise * static_cast<float>(std::sqrt(rng.uniform()));
    const float spin = static_cast<float>(rng.uniform() * 2.0 * std::numbers::pi);
    const glm::vec3 u = any_perpendicular(f), w = glm::cross(f, u);
    const glm::vec3 axis = std::cos(spin) * u + std::sin(spin) * w;
    const glm::quat qs = glm::normalize(glm::angleAxis(noise, axis) * p_.q[i]);
    const std::int32_t s = activate(i, h, qs, p_.shoot[i], p_.order[i], p_.rank[i] + 1, false);
    if (s < 0) break;  // the pool is full
    next.push_back(s);
    // Laterals (Leeuwenberg: B buds, each grows with probability BP), at V x 90 degrees.
    Rng branch(seed_, kBranchStream, idx * 16);
    if (p_.order[i] < cfg_.max_order) {
      for (int b = 0; b < cfg_.max_laterals; ++b) {
        const bool grows = branch.uniform() < cfg_.shoot_density;
        const double azimuth = branch.uniform() * 2.0 * std::numbers::pi;
        const double jitter = branch.uniform();
        if (!grows) continue;
        const float angle =
            cfg_.branch_variance * 0.5f * std::numbers::pi_v<float> * (1.0f - 0.3f * static_cast<float>(jitter));
        glm::quat ql = glm::normalize(p_.q[i] * glm::angleAxis(static_cast<float>(azimuth), kZ) *
                                      glm::angleAxis(angle, glm::vec3(1, 0, 0)));
        // On a support, a lateral leaves along it: its direction is laid into the surface's tangent
        // plane, keeping its side, so it does not start out into the air (where the plant could not
        // hold it up and it would hang).
        if (const glm::vec3 n = p_.normal[i]; glm::dot(n, n) > 0.0f) {
          const glm::vec3 d = ql * kZ;
          const glm::vec3 along = d - glm::dot(d, n) * n;
          if (glm::length(along) > 1e-3f) ql = glm::normalize(glm::rotation(d, glm::normalize(along)) * ql);
        }
        const std::int32_t l = activate(i, h, ql, next_shoot_, static_cast<std::uint16_t>(p_.order[i] + 1), 0, false);
        if (l < 0) break;
        ++next_shoot_;
        next.push_back(l);
      }
    }
    // A leaf at phyllotaxis sites.
    if (p_.rank[i] % static_cast<std::uint32_t>(cfg_.leaf_step) == 0) {
      Rng leaf(seed_, kLeafStream, idx);
      const double u1 = leaf.uniform(), u2 = leaf.uniform();
      const float site = static_cast<float>(p_.rank[i] / static_cast<std::uint32_t>(cfg_.leaf_step));
      const float azimuth = std::fmod(site * cfg_.phyllotaxis, 2.0f * std::numbers::pi_v<float>);
      if (u1 < cfg_.leaf_density) {
        leaves_.push_back({i, azimuth, cfg_.leaf_size * static_cast<float>(0.8 + 0.4 * u2)});
        ++live_leaves_;
      }
      // Drawn after the leaf's numbers, so flowers leave every leaf where it was.
      if (cfg_.flower_density > 0.0f && leaf.uniform() < cfg_.flower_density)
        flowers_.push_back({i, azimuth + std::numbers::pi_v<float>,
                            cfg_.flower_size * static_cast<float>(0.85 + 0.3 * leaf.uniform())});
    }
  }
  tips_.swap(next);  // surviving tips keep their order; new ones have higher indices
}

// Shape matching, pass 1: each particle's group (itself, its parent, its children) -> centroid,
// rest centroid and best rotation, from the predicted poses.
void Simulator::group_pass() {
  const std::size_t n = p_.size();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kGrain), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      if (!p_.has(i, Particles::Active)) continue;
      struct Member {
        std::size_t j;
        glm::vec3 rest_x;
        glm::quat rest_q;
        float mass = 0.0f;
      };
      std::array<Member, kMaxChildren + 2> m;
      std::size_t k = 0;
      m[k++] = {i, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), 0.0f};
      if (const std::int32_t par = p_.parent[i]; par >= 0) {
        const glm::vec3 o = rest_offset(static_cast<std::size_t>(par), i);
        const glm::quat rq = glm::conjugate(p_.rest[i]);
        m[k++] = {static_cast<std::size_t>(par), -(rq * o), rq, 0.0f};
      }
      for (const std::int32_t c : p_.children[i]) {
        if (c < 0) continue;
        const glm::vec3 o = rest_offset(i, static_cast<std::size_t>(c));
        m[k++] = {static_cast<std::size_t>(c), o, p_.rest[c], 0.0f};
      }
      if (k == 1) {  // a lone particle: nothing to match
        p_.group_c[i] = p_.xp[i];
        p_.group_cbar[i] = glm::vec3(0.0f);
        p_.group_r[i] = p_.qp[i];
        continue;
      }
      float mass = 0.0f;
      glm::vec3 c(0.0f), cbar(0.0f);
      for (std::size_t a = 0; a < k; ++a) {
        const std::size_t j = m[a].j;
        const float mj = m[a].mass = p_.half[j] * p_.radius[j] * p_.radius[j];
        mass += mj;
        c += mj * p_.xp[j];
        cbar += mj * m[a].rest_x;
      }
      c /= mass;
      cbar /= mass;
      glm::mat3 A(0.0f);
      for (std::size_t a = 0; a < k; ++a) {
        const std::size_t j = m[a].j;
        const float mj = m[a].mass;
        A += mj * glm::outerProduct(p_.xp[j] - c, m[a].rest_x - cbar);
        // The ellipsoid's own moment (Müller & Chentanez 2011): m/5 R diag(r^2, r^2, h^2) Rbar^T.
        const float r2 = p_.radius[j] * p_.radius[j], h2 = p_.half[j] * p_.half[j];
        A += (0.2f * mj) * (r2 * glm::mat3_cast(p_.qp[j] * glm::conjugate(m[a].rest_q)) +
                            (h2 - r2) * glm::outerProduct(p_.qp[j] * kZ, m[a].rest_q * kZ));
      }
      p_.group_c[i] = c;
      p_.group_cbar[i] = cbar;
      p_.group_r[i] = extract_rotation(A, p_.qp[i]);
    }
  });
}

// Shape matching, pass 2: each particle moves toward the mean of its goals in every group it belongs
// to (its own, its parent's, its children's) by the stiffness.
void Simulator::goal_pass() {
  const std::size_t n = p_.size();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kGrain), [&](const auto& range) {
    for (std::size_t j = range.begin(); j != range.end(); ++j) {
      p_.xp2[j] = p_.xp[j];
      p_.qp2[j] = p_.qp[j];
      if (!p_.has(j, Particles::Active) || p_.has(j, Particles::Pinned)) continue;
      glm::vec3 goal(0.0f);
      glm::quat qsum(0, 0, 0, 0);
      int count = 0;
      auto add = [&](std::size_t g, const glm::vec3& rest_x, const glm::quat& rest_q) {
        goal += p_.group_c[g] + p_.group_r[g] * (rest_x - p_.group_cbar[g]);
        glm::quat gq = p_.group_r[g] * rest_q;
        if (glm::dot(gq, p_.qp[j]) < 0.0f) gq = -gq;
        qsum = qsum + gq;
        ++count;
      };
      const bool has_group = p_.parent[j] >= 0 || std::any_of(p_.children[j].begin(), p_.children[j].end(),
                                                              [](std::int32_t c) { return c >= 0; });
      if (!has_group) continue;
      add(j, glm::vec3(0.0f), glm::quat(1, 0, 0, 0));
      if (const std::int32_t par = p_.parent[j]; par >= 0)
        add(static_cast<std::size_t>(par), rest_offset(static_cast<std::size_t>(par), j), p_.rest[j]);
      for (const std::int32_t c : p_.children[j]) {
        if (c < 0) continue;
        const glm::vec3 o = rest_offset(j, static_cast<std::size_t>(c));
        const glm::quat rq = glm::conjugate(p_.rest[c]);
        add(static_cast<std::size_t>(c), -(rq * o), rq);
      }
      goal /= static_cast<float>(count);
      const float s = cfg_.stiffness;
      p_.xp2[j] = p_.xp[j] + s * (goal - p_.xp[j]);
      const glm::quat qg = glm::normalize(qsum);
      p_.qp2[j] = glm::normalize(glm::quat(p_.qp[j].w + s * (qg.w - p_.qp[j].w), p_.qp[j].x + s * (qg.x - p_.qp[j].x),
                                           p_.qp[j].y + s * (qg.y - p_.qp[j].y), p_.qp[j].z + s * (qg.z - p_.qp[j].z)));
    }
  });
  p_.xp.swap(p_.xp2);
  p_.qp.swap(p_.qp2);
}

// Anchors, collision with the distance field, velocities from positions, friction and elasticity.
void Simulator::contact_pass() {
  const std::size_t n = p_.size();
  const float dt = cfg_.dt;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kGrain), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      if (!p_.has(i, Particles::Active)) continue;
      glm::vec3 xp = p_.xp[i];
      if (p_.has(i, Particles::Anchored)) {
        xp += cfg_.anchor_pull * (p_.anchor[i] - xp);
        if (glm::length(xp - p_.anchor[i]) > cfg_.anchor_release)
          p_.flags[i] &= static_cast<std::uint8_t>(~Particles::Anchored);
      }
      const glm::vec3 before = xp;
      // Pushed out to its longest semi-axis from the surface, plus its own share of the variability.
      const float body = std::max(p_.half[i], p_.radius[i]);
      float reach = body;
      // Kept inside the band: at its edge a particle would flip between pushed and free.
      if (cfg_.surface_variability > 0.0f)
        reach = std::max(body, std::min(body + surface_gap(i), kBandUse * query_.band_width()));
      SceneQuery::BandSample s = query_.band_sample(xp);
      if (!s.in_band && s.distance < 0.0f) {  // deep inside (beyond the band): exact distance and direction
        s.distance = query_.signed_distance(xp);
        s.gradient = query_.gradient(xp);
      }
      // A growing particle touches within a quarter of its reach beyond the contact distance (adaptation
      // brings tips parallel to a surface at about that distance, where the push-out alone would rarely
      // fire).
      if (p_.has(i, Particles::Growing) && s.in_band && s.distance < reach + 0.25f * body)
        p_.flags[i] |= Particles::Touched;
      bool contact = false;
      if ((s.in_band || s.distance < 0.0f) && s.distance < reach) {
        xp += (reach - s.distance) * s.gradient;
        contact = true;
        p_.normal[i] = s.gradient;
      }
      if (p_.has(i, Particles::Pinned)) xp = p_.x[i];
      glm::vec3 v = (xp - p_.x[i]) / dt;
      // A seed's first particle cannot be pushed out (its tail is the seed), so where it grows into a
      // curving surface it turns about its tail instead, as a growing tip turns along the surface below.
      if (contact && p_.has(i, Particles::Pinned) && p_.has(i, Particles::Growing)) {
        const glm::vec3 f = p_.qp[i] * kZ;
        const float fn = glm::dot(f, s.gradient);
        if (fn < 0.0f) {
          const glm::vec3 r = glm::normalize(f - (1.0f + cfg_.elasticity) * fn * s.gradient);
          p_.qp[i] = glm::normalize(glm::rotation(f, r) * p_.qp[i]);
          xp = p_.x[i] - f * p_.half[i] + r * p_.half[i];
        }
      }
      if (contact) {
        // The motion into the surface is reflected about its normal with the elasticity; friction
        // takes from the motion along it.
        const glm::vec3 pre = (before - p_.x[i]) / dt;
        const float vn = glm::dot(pre, s.gradient);
        const glm::vec3 vt = pre - vn * s.gradient;
        v = vt * (1.0f - cfg_.friction) + s.gradient * (vn < 0.0f ? -cfg_.elasticity * vn : vn);
        p_.flags[i] |= Particles::Contact;
        // A growing tip pointing into the surface is turned along it.
        if (p_.has(i, Particles::Growing) && !p_.has(i, Particles::Pinned)) {
          const glm::vec3 f = p_.qp[i] * kZ;
          const float fn = glm::dot(f, s.gradient);
          if (fn < 0.0f) {
            const glm::vec3 r = glm::normalize(f - (1.0f + cfg_.elasticity) * fn * s.gradient);
            p_.qp[i] = glm::normalize(glm::rotation(f, r) * p_.qp[i]);
            // (The parent is not growing, so its predicted pose is final in this pass.)
            if (p_.parent[i] >= 0) p_.rest[i] = glm::conjugate(p_.qp[p_.parent[i]]) * p_.qp[i];
          }
        }
      } else {
        p_.flags[i] &= static_cast<std::uint8_t>(~Particles::Contact);
      }
      glm::quat dq = p_.qp[i] * glm::conjugate(p_.q[i]);
      if (dq.w < 0.0f) dq = -dq;
      const glm::vec3 im(dq.x, dq.y, dq.z);
      const float sn = glm::length(im);
      glm::vec3 w = sn > 1e-9f ? im * (2.0f * std::atan2(sn, dq.w) / (sn * dt)) : glm::vec3(0.0f);
      const float keep = 1.0f - cfg_.damping;
      p_.v[i] = v * keep;
      p_.w[i] = w * keep;
      p_.x[i] = xp;
      p_.q[i] = p_.qp[i];
      if (p_.has(i, Particles::Pinned)) {  // the seed's tail stays; the particle may only grow along its axis
        p_.v[i] = glm::vec3(0.0f);
      }
      // Secondary growth.
      if (!p_.has(i, Particles::Growing))
        p_.radius[i] = std::min(max_radius(p_.order[i]), p_.radius[i] + cfg_.thickening * dt);
    }
  });
}

void Simulator::break_joints() {
  if (cfg_.break_sensitivity <= 0.0f) return;
  const float limit = cfg_.particle_length / cfg_.break_sensitivity;
  const std::size_t n = p_.size();
  std::vector<std::uint8_t> breaks(n, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kGrain), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const std::int32_t par = p_.parent[i];
      if (!p_.has(i, Particles::Active) || par < 0) continue;
      const glm::vec3 tail = p_.x[i] - forward(i) * p_.half[i];
      if (glm::length(tail - head(static_cast<std::size_t>(par))) > limit) breaks[i] = 1;
    }
  });
  for (std::size_t i = 0; i < n; ++i) {
    if (!breaks[i]) continue;
    auto& ch = p_.children[p_.parent[i]];
    *std::find(ch.begin(), ch.end(), static_cast<std::int32_t>(i)) = -1;
    p_.parent[i] = -1;
    ++roots_;
    ++broken_;
    ++version_;
  }
}

// The extra distance particle i keeps from surfaces: a smooth noise along its shoot (neighbours agree, so
// the shoot lifts off in waves rather than zigzags), in [0, surface_variability).
float Simulator::surface_gap(std::size_t i) const {
  const glm::vec2 at(static_cast<float>(p_.rank[i]) / 8.0f, static_cast<float>(p_.shoot[i] % 4096u) * 1.618f);
  return cfg_.surface_variability * 0.5f * (1.0f + glm::simplex(at + gap_offset_));
}

void Simulator::physics() {
  const std::size_t n = p_.size();
  const float dt = cfg_.dt;
  const glm::vec3 g(0.0f, -cfg_.gravity, 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kGrain), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      if (!p_.has(i, Particles::Active) || p_.has(i, Particles::Pinned)) {
        p_.xp[i] = p_.x[i];
        p_.qp[i] = p_.q[i];
        continue;
      }
      p_.xp[i] = p_.x[i] + p_.v[i] * dt + (g + wind(i)) * (0.5f * dt * dt);
      const float wl = glm::length(p_.w[i]);
      p_.qp[i] = wl > 1e-9f ? glm::normalize(glm::angleAxis(wl * dt, p_.w[i] / wl) * p_.q[i]) : p_.q[i];
    }
  });
  for (int it = 0; it < cfg_.iterations; ++it) {
    group_pass();
    goal_pass();
  }
  contact_pass();
  break_joints();
}

bool Simulator::step() {
  add_seeds();
  for (const Cut& c : cuts_)
    if (c.step == step_) prune(c.point, c.radius);
  if (!tips_.empty()) {
    if (cfg_.leaf_shadow > 0.0f) build_leaf_grid();
    grow_tips();
    spawn();
  }
  physics();
  ++step_;
  ++version_;
  const bool seeds_pending =
      std::any_of(seed_started_.begin(), seed_started_.end(), [](std::uint8_t s) { return s == 0; });
  return (!tips_.empty() && !pool_full_) || seeds_pending;
}

std::size_t Simulator::prune(const glm::vec3& point, float radius) {
  std::vector<std::int32_t> cut;
  if (radius > 0.0f) {
    for (std::size_t i = 0; i < p_.size(); ++i)
      if (p_.has(i, Particles::Active) && glm::length(head(i) - point) <= radius)
        cut.push_back(static_cast<std::int32_t>(i));
  } else {
    float best = std::numeric_limits<float>::infinity();
    std::int32_t nearest = -1;
    for (std::size_t i = 0; i < p_.size(); ++i) {
      const float d = glm::length(head(i) - point);
      if (p_.has(i, Particles::Active) && d < best) {
        best = d;
        nearest = static_cast<std::int32_t>(i);
      }
    }
    if (nearest >= 0) cut.push_back(nearest);
  }
  std::size_t removed = 0;
  for (const std::int32_t i : cut) removed += prune_subtree(i);
  return removed;
}

std::size_t Simulator::prune_subtree(std::int32_t root) {
  if (root < 0 || static_cast<std::size_t>(root) >= p_.size() || !p_.has(root, Particles::Active)) return 0;
  // Children have higher indices than their parents: one forward sweep finds the whole subtree.
  std::vector<std::uint8_t> dead(p_.size(), 0);
  dead[root] = 1;
  std::size_t removed = 0;
  for (std::size_t i = static_cast<std::size_t>(root); i < p_.size(); ++i) {
    if (i != static_cast<std::size_t>(root) && !(p_.parent[i] >= 0 && dead[p_.parent[i]])) continue;
    if (!p_.has(i, Particles::Active)) continue;
    dead[i] = 1;
    p_.flags[i] = 0;
    ++removed;
  }
  if (const std::int32_t par = p_.parent[root]; par >= 0) {
    auto& ch = p_.children[par];
    *std::find(ch.begin(), ch.end(), root) = -1;
  } else {
    --roots_;
  }
  // Broken-off pieces inside the subtree were roots of their own; they stay (they are not descendants).
  active_ -= removed;
  pruned_ += removed;
  std::erase_if(tips_, [&](std::int32_t t) { return dead[t] != 0; });
  for (const Leaf& l : leaves_)
    if (dead[l.particle]) --live_leaves_;
  std::erase_if(leaves_, [&](const Leaf& l) { return dead[l.particle] != 0; });
  std::erase_if(flowers_, [&](const Leaf& l) { return dead[l.particle] != 0; });
  ++version_;
  return removed;
}

const Plant& Simulator::plant() const {
  if (plant_version_ == version_ && !plant_.nodes.empty()) return plant_;
  plant_.clear();
  node_particle_.clear();
  plant_.nodes.reserve(active_ + roots_);
  std::vector<std::int32_t> node_of(p_.size(), -1);
  for (std::size_t i = 0; i < p_.size(); ++i) {
    if (!p_.has(i, Particles::Active)) continue;
    const glm::vec3 f = forward(i);
    std::int32_t parent_node = p_.parent[i] >= 0 ? node_of[p_.parent[i]] : kNoParent;
    if (parent_node == kNoParent) {  // a seed's first particle or a broken-off piece: a base node at its tail
      PlantNode base;
      base.position = p_.x[i] - f * p_.half[i];
      base.radius = p_.radius[i];
      base.order = p_.order[i];
      base.shoot = p_.shoot[i];
      base.birth_step = p_.birth[i];
      parent_node = static_cast<std::int32_t>(plant_.nodes.size());
      plant_.nodes.push_back(base);
      node_particle_.push_back(-1);
    }
    PlantNode n;
    n.position = p_.x[i] + f * p_.half[i];
    n.radius = p_.radius[i];
    n.parent = parent_node;
    n.order = p_.order[i];
    n.shoot = p_.shoot[i];
    n.birth_step = p_.birth[i];
    node_of[i] = static_cast<std::int32_t>(plant_.nodes.size());
    plant_.nodes.push_back(n);
    node_particle_.push_back(static_cast<std::int32_t>(i));
  }
  plant_.organs.reserve(leaves_.size() + flowers_.size());
  for (const Leaf& l : leaves_) {
    const auto i = static_cast<std::size_t>(l.particle);
    const glm::vec3 f = forward(i);
    const glm::vec3 at = p_.x[i] + f * p_.half[i];
    // Phyllotactic pose: the petiole leaves the stem at the site's azimuth, angled 40 degrees forward,
    // the blade's upper side facing away from the stem.
    const glm::vec3 side = p_.q[i] * glm::vec3(std::cos(l.azimuth), std::sin(l.azimuth), 0.0f);
    glm::vec3 blade = glm::normalize(0.77f * side + 0.64f * f);
    glm::vec3 up = glm::normalize(glm::cross(glm::cross(blade, side), blade) + 1e-6f * side);
    if (glm::dot(up, side) < 0.0f) up = -up;
    // Turned toward the light (or, against a surface that hides the light, away from the surface).
    const glm::vec3 ns = p_.normal[i];
    glm::vec3 want = scene_.light.towards(at);
    if (glm::length(ns) > 0.5f && glm::dot(want, ns) < 0.0f) want = ns;
    up = glm::normalize(glm::mix(up, want, cfg_.leaf_light) + 1e-6f * want);
    if (glm::length(ns) > 0.5f) blade -= std::min(0.0f, glm::dot(blade, ns)) * ns;  // not into the surface
    blade -= glm::dot(blade, up) * up;
    if (glm::length(blade) < 1e-5f) blade = any_perpendicular(up);
    blade = glm::normalize(blade);
    Organ o;
    o.position = at;
    o.orientation = glm::quat_cast(glm::mat3(glm::cross(up, blade), up, blade));
    o.size = l.size;
    o.kind = OrganKind::Leaf;
    o.node = node_of[i];
    plant_.organs.push_back(o);
  }
  for (const Leaf& fl : flowers_) plant_.organs.push_back(flower(fl, node_of[static_cast<std::size_t>(fl.particle)]));
  plant_version_ = version_;
  return plant_;
}

// A flower on a short stalk opposite its site's leaf, facing the light (+Z, the flower's face), or, where
// a surface hides the light, facing away from the surface.
Organ Simulator::flower(const Leaf& fl, std::int32_t node) const {
  const auto i = static_cast<std::size_t>(fl.particle);
  const glm::vec3 f = forward(i);
  const glm::vec3 side = p_.q[i] * glm::vec3(std::cos(fl.azimuth), std::sin(fl.azimuth), 0.0f);
  const glm::vec3 ns = p_.normal[i];
  glm::vec3 stalk = glm::normalize(side + f);
  if (glm::length(ns) > 0.5f) stalk -= std::min(0.0f, glm::dot(stalk, ns)) * ns;  // not into the surface
  const glm::vec3 at = p_.x[i] + f * p_.half[i] + 0.5f * fl.size * stalk;
  glm::vec3 face = scene_.light.towards(at);
  if (glm::length(ns) > 0.5f && glm::dot(face, ns) < 0.0f) face = ns;
  face = glm::normalize(face + 0.3f * side);
  const glm::vec3 up = glm::normalize(glm::cross(face, any_perpendicular(face)));
  Organ o;
  o.position = at;
  o.orientation = glm::quat_cast(glm::mat3(glm::cross(up, face), up, face));
  o.size = fl.size;
  o.kind = OrganKind::Flower;
  o.node = node;
  return o;
}

std::vector<std::pair<std::string, double>> Simulator::stats() const {
  std::size_t anchored = 0, contact = 0;
  float max_speed = 0.0f;
  for (std::size_t i = 0; i < p_.size(); ++i) {
    if (!p_.has(i, Particles::Active)) continue;
    anchored += p_.has(i, Particles::Anchored);
    contact += p_.has(i, Particles::Contact);
    max_speed = std::max(max_speed, glm::length(p_.v[i]));
  }
  return {{"particles", static_cast<double>(active_)},
          {"tips", static_cast<double>(tips_.size())},
          {"anchored", static_cast<double>(anchored)},
          {"in_contact", static_cast<double>(contact)},
          {"anchors_made", static_cast<double>(anchors_made_)},
          {"broken", static_cast<double>(broken_)},
          {"pruned", static_cast<double>(pruned_)},
          {"leaves", static_cast<double>(live_leaves_)},
          {"flowers", static_cast<double>(flowers_.size())},
          {"max_speed_m_s", static_cast<double>(max_speed)},
          {"pool_full", pool_full_ ? 1.0 : 0.0},
          {"bytes_per_particle", static_cast<double>(Particles::bytes_per_particle())}};
}

}  // namespace hadrich
}  // namespace growbench
