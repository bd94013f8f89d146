// Hädrich climbing plants: adaptation, phototropism, shade, collision, pruning, breaking, stability
// and determinism, each on a scene whose answer is known.
#include "algorithms/hadrich/hadrich.hpp"

#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "grow_util.hpp"
#include "scenes/geometry.hpp"
#include "scenes/scene_library.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

using hadrich::Particles;
using hadrich::Simulator;

hadrich::Setup setup(const std::vector<std::string>& sets) {
  Params p = default_params(find_algorithm("hadrich"));
  for (const auto& s : sets) p.set_assignment(s);
  return hadrich::make_setup(p);
}

// A lone wall in the plane z = 0 (front face at z = 0.05), a seed `gap` in front of it, sun overhead.
Scene wall_scene(float gap) {
  Scene s;
  s.name = "test-wall";
  s.meshes.push_back(geom::make_box("wall", {-1.0f, 0.0f, -0.05f}, {1.0f, 3.0f, 0.05f}));
  s.seeds.push_back({{0.0f, 0.05f, 0.05f + gap}, {0, 1, 0}, 0});
  s.light.direction = {0.0f, 1.0f, 0.0f};
  return s;
}

// Open space: one seed at the origin growing up, the sun in direction `light`, and only a small box far
// away (a scene needs a mesh).
Scene open_space(const glm::vec3& light) {
  Scene s;
  s.name = "test-open";
  s.meshes.push_back(geom::make_box("far", {10.0f, -0.1f, 10.0f}, {10.1f, 0.0f, 10.1f}));
  s.seeds.push_back({{0.0f, 0.0f, 0.0f}, {0, 1, 0}, 0});
  s.light.direction = light;
  return s;
}

// Distance from each particle of shoot 0 to the wall's front face, in growth order.
std::vector<float> main_shoot_gaps(const Simulator& sim) {
  std::vector<float> gaps;
  const Particles& p = sim.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.shoot[i] == 0 && p.has(i, Particles::Active)) gaps.push_back(p.x[i].z - 0.05f);
  return gaps;
}

TEST(Hadrich, PruneEntriesParseAndBadOnesAreNamed) {
  const auto cuts = hadrich::parse_cuts("0.1, 0.5,-0.2,0@40; 1,2,3,0.25@7;");
  ASSERT_EQ(cuts.size(), 2u);
  EXPECT_EQ(cuts[0].point, glm::vec3(0.1f, 0.5f, -0.2f));
  EXPECT_EQ(cuts[0].radius, 0.0f);
  EXPECT_EQ(cuts[0].step, 40);
  EXPECT_EQ(cuts[1].radius, 0.25f);
  EXPECT_EQ(cuts[1].step, 7);
  EXPECT_NE(test::error_of([] { hadrich::parse_cuts("1,2,3,0.1"); }).find("entry 1 '1,2,3,0.1': no '@step'"),
            std::string::npos);
  EXPECT_NE(test::error_of([] { hadrich::parse_cuts("1,2,3,0@4; 1,2,x,0@5"); }).find("entry 2"), std::string::npos);
  EXPECT_NE(test::error_of([] { hadrich::parse_cuts("1,2,0@4"); }).find("3 numbers"), std::string::npos);
  EXPECT_NE(test::error_of([] { hadrich::parse_cuts("1,2,3,-1@4"); }).find("negative radius"), std::string::npos);
  EXPECT_NE(test::error_of([] { hadrich::parse_cuts("1,2,3,1@-4"); }).find("step '-4'"), std::string::npos);
  // Through the parameter table, the error names the parameter.
  EXPECT_NE(test::error_of([] { setup({"prune=1,2,3@4"}); }).find("parameter 'prune'"), std::string::npos);
}

// A shoot started 8 cm in front of a wall, growing straight up (the light is overhead, so
// phototropism does not push it either way), bends onto the wall and stays there.
TEST(Hadrich, AdaptationPullsAShootOntoAWallAndKeepsItThere) {
  const Scene s = wall_scene(0.08f);
  SceneQuery q(s);
  Simulator sim(s, q, setup({"max_laterals=0", "max_particles=120", "direction_noise=0", "light_rays=0"}), 1);
  for (int i = 0; i < 600 && sim.step(); ++i) {
  }
  const auto gaps = main_shoot_gaps(sim);
  ASSERT_GE(gaps.size(), 100u);
  EXPECT_GT(gaps.front(), 0.06f);  // it started away from the wall
  // Every particle of the second half hugs the wall: centre within its contact distance plus a few mm.
  for (std::size_t k = gaps.size() / 2; k < gaps.size(); ++k) EXPECT_LT(gaps[k], 0.015f) << "particle " << k;
  for (const float g : gaps) EXPECT_GT(g, 0.0f);
  // The same shoot with adaptation off stays where it started.
  Simulator free(
      s, q, setup({"max_laterals=0", "max_particles=120", "direction_noise=0", "light_rays=0", "adaptation=0"}), 1);
  for (int i = 0; i < 600 && free.step(); ++i) {
  }
  const auto free_gaps = main_shoot_gaps(free);
  EXPECT_GT(free_gaps.back(), 0.07f);
}

// The Houdini tool's variability from surface: each particle keeps its own extra distance from the
// surface, up to the given amount, so the shoot hugs the wall less closely. It acts within the distance
// field's narrow band, so a wider band lets a larger variability act.
TEST(Hadrich, SurfaceVariabilityKeepsShootsFartherFromTheWall) {
  const Scene s = wall_scene(0.08f);
  auto settled_gap = [&](const SceneQuery& q, const std::string& variability) {
    Simulator sim(s, q,
                  setup({"max_laterals=0", "max_particles=120", "direction_noise=0", "light_rays=0",
                         "surface_variability=" + variability}),
                  1);
    for (int i = 0; i < 600 && sim.step(); ++i) {
    }
    const auto gaps = main_shoot_gaps(sim);
    double sum = 0.0;
    for (std::size_t k = gaps.size() / 2; k < gaps.size(); ++k) sum += gaps[k];
    return sum / static_cast<double>(gaps.size() - gaps.size() / 2);
  };
  const SceneQuery q(s);
  const double hug = settled_gap(q, "0"), loose = settled_gap(q, "0.02");
  // The extra distance is uniform in [0, 0.02): about 0.01 m on average.
  EXPECT_GT(loose - hug, 0.006) << hug << " -> " << loose;
  EXPECT_LT(loose - hug, 0.025) << hug << " -> " << loose;
  // The gap is capped at the distance field's band (the push-out acts only there): a wider band lets a
  // larger variability act, and neither sends the shoot off the wall.
  const SceneQuery wide(s, {.band_voxels = 12.0f});
  const double capped = settled_gap(q, "0.1"), free = settled_gap(wide, "0.1");
  EXPECT_LT(capped, q.band_width()) << capped;
  EXPECT_GT(free - capped, 0.01) << capped << " -> " << free;
  EXPECT_LT(free, 0.1 + 0.02) << free;
}

// The Houdini tool's starting velocity of new particles. In open space with the light overhead and no
// noise, the shoot grows straight up; a velocity along +z carries it toward +z, along -z toward -z.
TEST(Hadrich, StartVelocityCarriesTheShoot) {
  const Scene s = open_space({0.0f, 1.0f, 0.0f});
  SceneQuery q(s);
  auto mean_z = [&](const std::string& set) {
    Simulator sim(s, q, setup({"max_laterals=0", "max_particles=60", "direction_noise=0", "gravity=0", set}), 1);
    for (int i = 0; i < 400 && sim.step(); ++i) {
    }
    double z = 0.0;
    for (std::size_t i = 0; i < sim.particles().size(); ++i) z += sim.particles().x[i].z;
    return z / static_cast<double>(sim.particles().size());
  };
  EXPECT_NEAR(mean_z("start_velocity=0,0,0"), 0.0, 1e-6);
  EXPECT_GT(mean_z("start_velocity=0,0,0.5"), 0.05);
  EXPECT_LT(mean_z("start_velocity=0,0,-0.5"), -0.05);
}

// In open space with the sun to the side (+x, up), the shoot turns toward it; with phototropism off it
// keeps growing straight up.
TEST(Hadrich, PhototropismTurnsTowardTheLight) {
  const Scene s = open_space({1.0f, 0.2f, 0.0f});
  SceneQuery q(s);
  auto tip_direction = [&](const std::vector<std::string>& sets) {
    auto sets2 = sets;
    for (const char* x : {"max_laterals=0", "max_particles=60", "direction_noise=0", "gravity=0"})
      sets2.emplace_back(x);
    Simulator sim(s, q, setup(sets2), 1);
    for (int i = 0; i < 400 && sim.step(); ++i) {
    }
    return sim.forward(sim.particles().size() - 1);
  };
  const glm::vec3 lit = tip_direction({});
  const glm::vec3 none = tip_direction({"phototropism=0"});
  const glm::vec3 l = glm::normalize(s.light.direction);
  EXPECT_GT(glm::dot(lit, l), 0.99f);  // turned all the way to the light
  EXPECT_NEAR(glm::dot(none, glm::vec3(0, 1, 0)), 1.0f, 1e-4f);
}

// A roof over one seed shades it: its tips see O = 1, it grows at shade_growth of the speed, and it
// ends shorter than the seed in the sun after the same number of steps.
TEST(Hadrich, GrowthSlowsInTheShade) {
  Scene s;
  s.name = "test-shade";
  s.meshes.push_back(geom::make_box("roof", {-0.5f, 2.0f, -0.5f}, {0.5f, 2.1f, 0.5f}));
  s.seeds.push_back({{0.0f, 0.0f, 0.0f}, {0, 1, 0}, 0});
  s.seeds.push_back({{3.0f, 0.0f, 0.0f}, {0, 1, 0}, 0});
  s.light.direction = {0.0f, 1.0f, 0.0f};
  SceneQuery q(s);
  Simulator sim(s, q,
                setup({"max_laterals=0", "direction_noise=0", "phototropism=0", "gravity=0", "shade_growth=0.25"}), 1);
  for (int i = 0; i < 100; ++i) sim.step();
  const Particles& p = sim.particles();
  float shaded = 0.0f, sunny = 0.0f;
  for (std::size_t i = 0; i < p.size(); ++i) (p.shoot[i] == 0 ? shaded : sunny) += 2.0f * p.half[i];
  EXPECT_NEAR(shaded / sunny, 0.25f, 0.02f);
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.has(i, Particles::Growing)) {
      EXPECT_EQ(p.light[i], p.shoot[i] == 0 ? 0.0f : 1.0f);
    }
}

// The standard boulder is climbed: its seeds stand at its foot, under the bulge, and the shoots must
// reach the rock and hold to it rather than sag onto the ground beside it. Counted over three seeds:
// nodes higher than the seeds could reach without the rock (0.3 m) and within 5 cm of its surface.
// Whether one shoot makes it past the overhang is sensitive to rounding (another compiler's flags can
// tip it), so the test pools seeds rather than trusting one plant.
TEST(Hadrich, ShootsClimbTheBoulder) {
  const Scene s = load_scene("boulder");
  SceneQuery q(s);
  std::size_t on_rock = 0, nodes = 0;
  std::string each;
  for (const std::uint64_t seed : {1, 2, 3}) {
    const Plant plant = test::grow("hadrich", s, q, {}, 0, seed);
    std::size_t n = 0;
    for (const auto& node : plant.nodes)
      n += node.position.y > 0.3f && q.signed_distance(node.position) < 0.05f ? 1 : 0;
    on_rock += n;
    nodes += plant.nodes.size();
    each += fmt::format(" seed {}: {} of {};", seed, n, plant.nodes.size());
  }
  EXPECT_GT(static_cast<double>(on_rock) / static_cast<double>(nodes), 0.3) << "nodes on the rock:" << each;
}

// Flowers come from the leaf pass: with flower_density, some sites carry one, every leaf stays where
// it was (the flower's numbers are drawn after the leaf's), and each flower faces the light or away
// from the surface it grows on, never into it.
TEST(Hadrich, FlowersJoinTheLeavesAndFaceOut) {
  const Scene s = load_scene("wall");
  SceneQuery q(s);
  const Plant bare = test::grow("hadrich", s, q, {"max_particles=2000"});
  const Plant flowering = test::grow("hadrich", s, q, {"max_particles=2000", "flower_density=0.3"});
  std::vector<const Organ*> leaves, flowers;
  for (const auto& o : flowering.organs) (o.kind == OrganKind::Flower ? flowers : leaves).push_back(&o);
  ASSERT_EQ(leaves.size(), bare.organs.size());
  for (std::size_t k = 0; k < leaves.size(); ++k) EXPECT_EQ(leaves[k]->position, bare.organs[k].position);
  for (const auto& o : bare.organs) EXPECT_EQ(o.kind, OrganKind::Leaf);
  // About 0.3 of the sites: the sites are those with a leaf (density 0.7) and those without.
  const double sites = static_cast<double>(leaves.size()) / 0.7;
  EXPECT_GT(static_cast<double>(flowers.size()), 0.2 * sites);
  EXPECT_LT(static_cast<double>(flowers.size()), 0.4 * sites);
  const glm::vec3 light = glm::normalize(s.light.direction);
  for (const Organ* f : flowers) {
    const glm::vec3 face = f->orientation * glm::vec3(0, 0, 1);
    const glm::vec3 n = q.gradient(f->position);
    EXPECT_TRUE(glm::dot(face, light) > 0.0f || glm::dot(face, n) > 0.0f) << "a flower faces into the wall";
    EXPECT_GT(q.signed_distance(f->position), 0.0f);
    EXPECT_GE(f->node, 0);
  }
}

// Closed solids: no plant node inside the column, the boulder or the bunny.
TEST(Hadrich, NoNodeInsideClosedSolids) {
  for (const std::string name : {"column", "boulder"}) {
    const Scene s = load_scene(name);
    SceneQuery q(s);
    const Plant plant = test::grow("hadrich", s, q, {"max_particles=3000"});
    ASSERT_GT(plant.nodes.size(), 2000u) << name;
    const auto inside = test::nodes_inside_solids(plant, q);
    EXPECT_TRUE(inside.empty()) << name << ": " << inside.size() << " nodes inside";
  }
  Scene bunny = load_scene("mesh:stanford-bunny");
  SceneQuery q(bunny);
  const Plant plant = test::grow("hadrich", bunny, q, {"max_particles=3000"});
  ASSERT_GT(plant.nodes.size(), 2000u);
  const auto inside = test::nodes_inside_solids(plant, q);
  EXPECT_TRUE(inside.empty()) << inside.size() << " nodes inside the bunny";
}

// Pruning a particle removes it and exactly its descendants (found here independently, by walking up
// the parent links of every particle), with their leaves, and nothing else.
TEST(Hadrich, PruningRemovesExactlyTheSubtree) {
  const Scene s = load_scene("wall");
  SceneQuery q(s);
  Simulator sim(s, q, setup({"max_particles=6000"}), 3);
  for (int i = 0; i < 250; ++i) ASSERT_TRUE(sim.step());
  const Particles& p = sim.particles();
  // A particle with a lateral among its descendants, a quarter of the way into the pool.
  std::int32_t cut = -1;
  for (std::size_t i = p.size() / 4; i < p.size() && cut < 0; ++i)
    if (p.parent[i] >= 0 &&
        std::count_if(p.children[i].begin(), p.children[i].end(), [](std::int32_t c) { return c >= 0; }) >= 2)
      cut = static_cast<std::int32_t>(i);
  ASSERT_GE(cut, 0);
  std::set<std::size_t> expected_removed, survivors;
  for (std::size_t i = 0; i < p.size(); ++i) {
    bool below = false;
    for (std::int32_t a = static_cast<std::int32_t>(i); a >= 0; a = p.parent[a]) below = below || a == cut;
    (below ? expected_removed : survivors).insert(i);
  }
  ASSERT_GT(expected_removed.size(), 2u);
  std::size_t leaves_kept = 0;
  const Plant before = sim.plant();
  const auto& node_particle = sim.node_particles();
  for (const Organ& o : before.organs)
    if (!expected_removed.count(static_cast<std::size_t>(node_particle[o.node]))) ++leaves_kept;

  EXPECT_EQ(sim.prune_subtree(cut), expected_removed.size());
  std::set<std::size_t> active;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.has(i, Particles::Active)) active.insert(i);
  EXPECT_EQ(active, survivors);
  const Plant after = sim.plant();
  EXPECT_EQ(after.validate(), "");
  EXPECT_EQ(after.organs.size(), leaves_kept);
  EXPECT_EQ(sim.node_count(), after.nodes.size());
  EXPECT_EQ(sim.leaf_count(), after.organs.size());
  // The parent of the cut particle no longer lists it; growth goes on.
  const auto& ch = p.children[p.parent[cut]];
  EXPECT_EQ(std::count(ch.begin(), ch.end(), cut), 0);
  EXPECT_TRUE(sim.step());
}

// The `prune` parameter cuts during the run at its step: radius 0 takes the particle nearest the
// point, a radius every particle whose head is within it. The point is a particle's head at that step,
// found by a first run (runs are deterministic).
TEST(Hadrich, PruneParameterCutsAtItsStep) {
  const Scene s = load_scene("wall", {"seeds=1"});
  SceneQuery q(s);
  Simulator probe(s, q, setup({"max_particles=2000"}), 1);
  for (int i = 0; i < 150; ++i) probe.step();
  const std::size_t before = probe.node_count();
  std::vector<glm::vec3> heads;
  for (std::size_t k = 0; k < probe.particles().size(); ++k) heads.push_back(probe.head(k));
  const std::size_t target = heads.size() / 2;
  const glm::vec3 at = heads[target];
  for (const float radius : {0.0f, 0.1f}) {
    Simulator sim(s, q, setup({"max_particles=2000", fmt::format("prune={},{},{},{}@150", at.x, at.y, at.z, radius)}),
                  1);
    for (int i = 0; i < 150; ++i) sim.step();
    EXPECT_EQ(sim.node_count(), before);
    sim.step();
    double pruned = 0.0;
    for (const auto& [k, v] : sim.stats())
      if (k == "pruned") pruned = v;
    EXPECT_GE(pruned, 1.0) << radius;
    EXPECT_FALSE(sim.particles().has(target, Particles::Active));
    for (std::size_t k = 0; k < heads.size(); ++k) {
      if (glm::length(heads[k] - at) <= radius) {
        EXPECT_FALSE(sim.particles().has(k, Particles::Active)) << k;
      }
    }
  }
}

// Under a gale, joints break when breaking is on, and never when its sensitivity is 0.
TEST(Hadrich, BreakingUnderLoadAndNeverWithSensitivityZero) {
  Scene s;
  s.name = "test-gale";
  s.meshes.push_back(geom::make_box("ground", {-5.0f, -0.1f, -5.0f}, {5.0f, 0.0f, 5.0f}));
  s.seeds.push_back({{0.0f, 0.02f, 0.0f}, {0, 1, 0}, 0});
  SceneQuery q(s);
  auto broken = [&](const char* sensitivity) {
    Simulator sim(
        s, q,
        setup({"max_particles=150", "max_laterals=0", "gravity=0", "wind_strength=400", "wind=1,0,0", sensitivity}), 1);
    for (int i = 0; i < 800; ++i) sim.step();
    std::size_t roots = 0;
    for (const auto& n : sim.plant().nodes) roots += n.parent == kNoParent ? 1 : 0;
    for (const auto& [k, v] : sim.stats())
      if (k == "broken") {
        EXPECT_EQ(static_cast<double>(roots - 1), v);
      }
    EXPECT_EQ(sim.plant().validate(), "");
    return roots - 1;
  };
  EXPECT_GT(broken("break_sensitivity=2"), 0u);
  EXPECT_EQ(broken("break_sensitivity=0"), 0u);
}

// 10,000 steps at the default time step with wind and gusts: finite, bounded, nothing escapes.
TEST(Hadrich, StableOverTenThousandSteps) {
  const Scene s = load_scene("corner", {"seeds=1"});
  SceneQuery q(s);
  Simulator sim(s, q, setup({"max_particles=400", "wind_strength=3", "wind_gusts=1"}), 2);
  float worst = 0.0f;
  const Aabb box = s.bounds();
  for (int i = 0; i < 10000; ++i) {
    sim.step();
    if (i % 500 != 499) continue;
    const Particles& p = sim.particles();
    for (std::size_t k = 0; k < p.size(); ++k) {
      ASSERT_TRUE(std::isfinite(p.x[k].x + p.x[k].y + p.x[k].z + p.v[k].x + p.v[k].y + p.v[k].z)) << "step " << i;
      worst = std::max(worst, glm::length(p.v[k]));
      ASSERT_TRUE(box.contains(p.x[k]) || glm::length(p.x[k] - box.center()) < 10.0f) << "escaped at step " << i;
    }
  }
  EXPECT_LT(worst, 5.0f);  // m/s; a shoot at rest under wind moves far slower
  EXPECT_EQ(sim.plant().validate(), "");
}

TEST(Hadrich, SamePlantForAnyThreadCountAndRun) {
  const Scene s = load_scene("corner");
  SceneQuery q(s);
  const std::vector<std::string> sets = {"max_particles=3000", "wind_strength=2", "break_sensitivity=1",
                                         "leaf_shadow=1"};
  const Plant one = test::grow("hadrich", s, q, sets, 1, 5);
  const Plant two = test::grow("hadrich", s, q, sets, 2, 5);
  const Plant again = test::grow("hadrich", s, q, sets, 2, 5);
  EXPECT_EQ(one.geometry_hash(), two.geometry_hash());
  EXPECT_EQ(two.geometry_hash(), again.geometry_hash());
  EXPECT_GT(one.nodes.size(), 2000u);
  EXPECT_NE(one.geometry_hash(), test::grow("hadrich", s, q, sets, 2, 6).geometry_hash());
}

// With leaf_shadow, a plant's own leaves shade its tips: in open space under an overhead sun, where the
// scene shades nothing, some tips see less than full light, and none sees none. Without it every tip
// sees full light.
TEST(Hadrich, LeafShadowShadesTipsBelowTheLeaves) {
  const Scene s = open_space({0.0f, 1.0f, 0.0f});
  SceneQuery q(s);
  auto tip_light = [&](const std::string& shadow) {
    Simulator sim(s, q, setup({"max_particles=1500", "gravity=0", "shoot_density=0.3", "leaf_shadow=" + shadow}), 1);
    for (int i = 0; i < 2000 && sim.step(); ++i) {
    }
    std::vector<float> light;
    const Particles& p = sim.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.has(i, Particles::Growing)) light.push_back(p.light[i]);
    return light;
  };
  for (const float l : tip_light("0")) EXPECT_EQ(l, 1.0f);
  const std::vector<float> shaded = tip_light("2");
  ASSERT_FALSE(shaded.empty());
  const auto dim = std::count_if(shaded.begin(), shaded.end(), [](float l) { return l < 0.9f; });
  EXPECT_GT(dim, 0) << "no tip was shaded by the leaves above it";
  for (const float l : shaded) {
    EXPECT_GT(l, 0.0f);
    EXPECT_LE(l, 1.0f);
  }
}

// The leaves sit on their particles, face the light (the sun is in front of the wall) or away from
// the surface, and the plant on the wall is mostly attached.
TEST(Hadrich, WallPlantClimbsAndLeavesFaceOut) {
  const Scene s = load_scene("wall");
  SceneQuery q(s);
  const Plant plant = test::grow("hadrich", s, q, {"max_particles=4000"});
  ASSERT_GT(plant.organs.size(), 1000u);
  std::size_t facing = 0, near = 0;
  float top = 0.0f;
  for (const Organ& o : plant.organs) {
    const glm::vec3 up = o.orientation * glm::vec3(0, 1, 0);
    facing += glm::dot(up, glm::vec3(0, 0, 1)) > 0.0f ? 1 : 0;
    EXPECT_EQ(o.position, plant.nodes[o.node].position);
  }
  for (const auto& n : plant.nodes) {
    near += q.closest_point(n.position, 0.03f, true).found ? 1 : 0;
    top = std::max(top, n.position.y);
  }
  EXPECT_GT(static_cast<double>(facing) / plant.organs.size(), 0.9);
  EXPECT_GT(static_cast<double>(near) / plant.nodes.size(), 0.5);
  EXPECT_GT(top, 1.0f);  // it climbed
}

// Hugging, not sprawling: on the corner and on the bunny (whose ground is not climbable) most of the
// plant is up on the climbable surfaces and close to them. Under too strong a gravity the shoots peel
// off and lie on the ground (README, "Gravity is below Earth's").
TEST(Hadrich, PlantsClimbTheCornerAndTheBunnyRatherThanTheGround) {
  for (const std::string& name : std::vector<std::string>{"corner", "mesh:stanford-bunny"}) {
    Scene s = load_scene(name);
    SceneQuery q(s);
    // The bunny's default seed is on the rim of its sealed base, which leans a few centimetres over the
    // ground: particles from there creep into that wedge. On its flank the question is the climbing.
    if (name != "corner") s.seeds = {{q.closest_point({0.0f, 0.8f, 1.0f}).point, {0, 1, 0}, 0}};
    const Plant plant = test::grow("hadrich", s, q, {"max_particles=3000"});
    ASSERT_GT(plant.nodes.size(), 2000u) << name;
    std::vector<float> height;
    std::size_t up_and_on = 0;
    for (const auto& n : plant.nodes) {
      height.push_back(n.position.y);
      up_and_on += n.position.y > 0.3f && q.closest_point(n.position, 0.05f, true).found ? 1 : 0;
    }
    std::nth_element(height.begin(), height.begin() + height.size() / 2, height.end());
    EXPECT_GT(height[height.size() / 2], 0.15f) << name << ": the median node is near the ground";
    EXPECT_GT(static_cast<double>(up_and_on) / plant.nodes.size(), 0.3) << name;
  }
}

}  // namespace
}  // namespace growbench
