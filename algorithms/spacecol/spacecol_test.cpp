#include <filesystem>

#include <gtest/gtest.h>

#include "algorithms/algorithm.hpp"
#include "grow_util.hpp"
#include "scenes/geometry.hpp"
#include "scenes/scene_library.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

using test::grow;

// An empty world: one small box far away (a scene needs a mesh), seeds as given.
Scene open_space(std::vector<glm::vec3> seeds) {
  Scene s;
  s.name = "space";
  s.meshes.push_back(geom::make_box("far", {50, 50, 50}, {51, 51, 51}));
  for (const auto& p : seeds) s.seeds.push_back({p, {0, 1, 0}, 0});
  return s;
}

std::string points_file(const std::string& name, const std::string& text) {
  return test::write_text(test::temp_dir(name) / "points.txt", text);
}

std::vector<std::string> exact(const std::string& file, std::vector<std::string> more = {}) {
  std::vector<std::string> v = {"points=file", "points_file=" + file, "influence=2", "kill=0.05",
                                "step=0.02",   "leaves=none",         "seek=false"};
  v.insert(v.end(), more.begin(), more.end());
  return v;
}

int children_of(const Plant& p, int node) {
  int n = 0;
  for (const auto& x : p.nodes) n += x.parent == node ? 1 : 0;
  return n;
}

TEST(SpaceColonization, OnePointGivesAStraightChainEndingWithinKillDistance) {
  const Scene s = open_space({{0, 0, 0}});
  SceneQuery q(s, {.build_sdf = false});
  const float d = 1.0f, kill = 0.05f, step = 0.02f;
  const Plant p = grow("spacecol", s, q, exact(points_file("one", "# a single point\n1 0 0\n")));
  // Nodes are added until one is within the kill distance: ceil((d - kill) / step) of them after the root.
  const auto expected = static_cast<std::size_t>(std::ceil((d - kill) / step));
  ASSERT_EQ(p.nodes.size(), expected + 1);
  for (std::size_t i = 1; i < p.nodes.size(); ++i) {
    EXPECT_EQ(p.nodes[i].parent, static_cast<std::int32_t>(i - 1));
    EXPECT_EQ(p.nodes[i].position.y, 0.0f);
    EXPECT_EQ(p.nodes[i].position.z, 0.0f);
    EXPECT_NEAR(p.nodes[i].position.x - p.nodes[i - 1].position.x, step, 1e-6f);
  }
  const float last = d - p.nodes.back().position.x;
  EXPECT_LT(last, kill);
  EXPECT_GE(last, kill - step);
}

TEST(SpaceColonization, TwoSymmetricPointsBranch) {
  const Scene s = open_space({{0, 0, 0}});
  SceneQuery q(s, {.build_sdf = false});
  const std::string f = points_file("two", "-1 0 0\n1 0 0\n");
  const Plant p = grow("spacecol", s, q, exact(f));
  EXPECT_EQ(children_of(p, 0), 2);
  EXPECT_EQ(p.nodes.size(), 1u + 2u * 48u);
  float min_x = 0, max_x = 0;
  for (const auto& n : p.nodes) {
    min_x = std::min(min_x, n.position.x);
    max_x = std::max(max_x, n.position.x);
    EXPECT_EQ(n.position.y, 0.0f);
  }
  EXPECT_GT(max_x, 0.95f);
  EXPECT_LT(min_x, -0.95f);
  // With splitting off, the pulls cancel and the root stalls instead.
  std::vector<std::pair<std::string, double>> stats;
  const Plant stalled = grow("spacecol", s, q, exact(f, {"split=0"}), 0, 1, 5000, &stats);
  EXPECT_EQ(stalled.nodes.size(), 1u);
  // And a trunk grown toward two points above it splits where their pulls start to cancel.
  const Plant y = grow("spacecol", s, q, exact(points_file("twoup", "-0.5 1 0\n0.5 1 0\n")));
  int forks = 0;
  for (std::size_t i = 0; i < y.nodes.size(); ++i) forks += children_of(y, static_cast<int>(i)) == 2 ? 1 : 0;
  EXPECT_EQ(forks, 1);
}

// Mean angle between each segment and its parent's, in radians.
double mean_turn(const Plant& p) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < p.nodes.size(); ++i) {
    const std::int32_t a = p.nodes[i].parent;
    if (a < 0 || p.nodes[static_cast<std::size_t>(a)].parent < 0) continue;
    const glm::vec3 s0 = p.nodes[static_cast<std::size_t>(a)].position -
                         p.nodes[static_cast<std::size_t>(p.nodes[static_cast<std::size_t>(a)].parent)].position;
    const glm::vec3 s1 = p.nodes[i].position - p.nodes[static_cast<std::size_t>(a)].position;
    sum += std::acos(std::clamp(glm::dot(glm::normalize(s0), glm::normalize(s1)), -1.0f, 1.0f));
    ++n;
  }
  return n > 0 ? sum / n : 0.0;
}

// The Hyphae notes add noise(CLPOS), a smooth field of position: a chain toward one point wanders, but
// each step turns only a little. A fresh random vector per step turns it sharply every step.
TEST(SpaceColonization, PositionNoiseBendsSmoothlyRandomNoiseJitters) {
  const Scene s = open_space({{0, 0, 0}});
  SceneQuery q(s, {.build_sdf = false});
  const std::string one = points_file("noise", "1 0 0\n");
  const Plant smooth = grow("spacecol", s, q, exact(one, {"noise=0.5", "noise_scale=0.5"}));
  const Plant jitter = grow("spacecol", s, q, exact(one, {"noise=0.5", "noise_field=random"}));
  float off_axis = 0.0f;
  for (const auto& n : smooth.nodes) off_axis = std::max(off_axis, std::hypot(n.position.y, n.position.z));
  EXPECT_GT(off_axis, 0.02f) << "the noise must bend the chain off the straight line";
  EXPECT_LT(glm::distance(smooth.nodes.back().position, glm::vec3(1, 0, 0)), 0.05f) << "and it still arrives";
  EXPECT_LT(mean_turn(smooth), 0.25 * mean_turn(jitter)) << mean_turn(smooth) << " vs " << mean_turn(jitter);
  EXPECT_GT(mean_turn(jitter), 0.2);
  EXPECT_NE(grow("spacecol", s, q, exact(one, {"noise=0.5", "noise_scale=0.5"}), 1, 2).geometry_hash(),
            smooth.geometry_hash())
      << "each seed reads its own part of the field";
}

// The Hyphae notes' fix for veins that stop at the first points they reach: more points toward the
// volume's centre. The nodes follow the points inward.
TEST(SpaceColonization, CenterDensityDrawsTheVeinsInward) {
  const Scene s = load_scene("envelope");
  const SceneQuery q(s);
  const Shape& env = *s.envelope;
  auto mean_depth = [&](const Plant& p) {
    double sum = 0.0;
    for (const auto& n : p.nodes) sum += glm::length((n.position - env.center) / env.radii);
    return sum / static_cast<double>(p.nodes.size());
  };
  const Plant flat = grow("spacecol", s, q, {"point_count=3000", "leaves=none"});
  const Plant dense = grow("spacecol", s, q, {"point_count=3000", "leaves=none", "center_density=4"});
  ASSERT_EQ(env.kind, Shape::Kind::Sphere);
  EXPECT_LT(mean_depth(dense), 0.9 * mean_depth(flat)) << mean_depth(dense) << " vs " << mean_depth(flat);
}

TEST(SpaceColonization, OpenAndClosedVenationDiffer) {
  // Two roots equidistant from one point. Open venation: the point pulls only its nearest node (ties
  // to the lower index), so one vein grows. Closed: both roots are in its relative neighbourhood, both
  // veins grow until each is within the kill distance (they meet at the source: a loop).
  const Scene s = open_space({{-1, 0, 0}, {1, 0, 0}});
  SceneQuery q(s, {.build_sdf = false});
  const std::string f = points_file("openclosed", "0 1 0\n");
  const Plant open = grow("spacecol", s, q, exact(f, {"venation=open"}));
  const Plant closed = grow("spacecol", s, q, exact(f, {"venation=closed"}));
  EXPECT_EQ(children_of(open, 0), 1);
  EXPECT_EQ(children_of(open, 1), 0);
  EXPECT_EQ(children_of(closed, 0), 1);
  EXPECT_EQ(children_of(closed, 1), 1);
  int tips_near = 0;
  for (std::size_t i = 0; i < closed.nodes.size(); ++i)
    if (children_of(closed, static_cast<int>(i)) == 0 &&
        glm::length(closed.nodes[i].position - glm::vec3(0, 1, 0)) < 0.05f)
      ++tips_near;
  EXPECT_EQ(tips_near, 2);
}

TEST(SpaceColonization, SeekGrowsTheTrunkUpToTheCrown) {
  const Scene s = load_scene("envelope");
  SceneQuery q(s);
  const Plant p = grow("spacecol", s, q, {"point_count=3000"});
  ASSERT_GT(p.nodes.size(), 100u);
  float top = 0;
  for (const auto& n : p.nodes) top = std::max(top, n.position.y);
  EXPECT_GT(top, 2.2f);  // reached well into the crown (centre at 2.2 m)
  const Plant no_seek = grow("spacecol", s, q, {"point_count=3000", "seek=false"});
  EXPECT_EQ(no_seek.nodes.size(), 1u);  // nothing within reach of the root
}

void expect_outside_solids(const char* what, const SceneQuery& q, const Plant& p, float max_off_surface) {
  float worst = std::numeric_limits<float>::infinity(), farthest = 0;
  std::size_t inside = 0;
  for (const auto& n : p.nodes) {
    const float d = q.signed_distance(n.position);
    worst = std::min(worst, d);
    farthest = std::max(farthest, d);
    inside += q.inside(n.position) ? 1 : 0;
  }
  EXPECT_EQ(inside, 0u) << what << ": nodes inside a solid";
  EXPECT_GE(worst, -q.inside_screen()) << what << ": the field reads a node deep inside";
  EXPECT_LE(farthest, max_off_surface) << what;
}

TEST(SpaceColonization, AvoidAndClingKeepNodesOutOfSolids) {
  const Scene column = load_scene("column");
  SceneQuery qc(column);
  const Plant avoid = grow("spacecol", column, qc, {"surface=avoid", "point_count=5000"});
  ASSERT_GT(avoid.nodes.size(), 200u);
  expect_outside_solids("column/avoid", qc, avoid, 100.0f);
  const Plant cling = grow("spacecol", column, qc, {"surface=cling", "point_count=5000"});
  ASSERT_GT(cling.nodes.size(), 200u);
  expect_outside_solids("column/cling", qc, cling, 0.03f);
}

TEST(SpaceColonization, FreeGrowsThroughAWallAvoidDoesNot) {
  Scene s = load_scene("wall");  // the wall fills z in [-0.1, 0.1]
  s.seeds = {{{0, 1, 0.3f}, {0, 1, 0}, 0}};
  SceneQuery q(s);
  const std::string f = points_file("behind", "0 1 -0.5\n");
  auto inside_count = [&](const Plant& p) {
    int n = 0;
    for (const auto& node : p.nodes) n += q.signed_distance(node.position) < 0.0f ? 1 : 0;
    return n;
  };
  const Plant free_plant = grow("spacecol", s, q, exact(f, {"surface=free"}));
  EXPECT_GT(inside_count(free_plant), 5);
  const Plant avoid = grow("spacecol", s, q, exact(f, {"surface=avoid"}));
  EXPECT_EQ(inside_count(avoid), 0);
  EXPECT_GT(avoid.nodes.size(), 5u);
  for (const auto& n : avoid.nodes) EXPECT_GT(n.position.z, 0.1f);  // stopped in front of the wall
  // A collision-only wall (not drawn) stops the plant all the same.
  for (auto& m : s.meshes) m.visible = false;
  SceneQuery hidden(s);
  EXPECT_EQ(grow("spacecol", s, hidden, exact(f, {"surface=avoid"})).geometry_hash(), avoid.geometry_hash());
}

TEST(SpaceColonization, ClingStaysOnTheBunny) {
  const Scene bunny = load_scene("mesh:stanford-bunny");
  SceneQuery q(bunny);
  const Plant p = grow("spacecol", bunny, q, {"surface=cling", "point_count=8000"});
  ASSERT_GT(p.nodes.size(), 500u);
  expect_outside_solids("bunny/cling", q, p, 0.03f);
  for (const auto& o : p.organs) EXPECT_GT(q.signed_distance(o.position), -1e-3f);
}

TEST(SpaceColonization, DeterministicAcrossThreadCountsAndRuns) {
  const Scene s = load_scene("wall");
  SceneQuery q(s);
  for (const auto& sets : std::vector<std::vector<std::string>>{{"point_count=8000"},
                                                                {"point_count=4000", "venation=closed"},
                                                                {"point_count=6000", "noise=0.3", "surface=cling"}}) {
    const std::string h1 = grow("spacecol", s, q, sets, 1).geometry_hash();
    const std::string h2 = grow("spacecol", s, q, sets, 2).geometry_hash();
    const std::string h2b = grow("spacecol", s, q, sets, 2).geometry_hash();
    EXPECT_EQ(h1, h2) << sets.back();
    EXPECT_EQ(h2, h2b) << sets.back();
    EXPECT_NE(h1, grow("spacecol", s, q, sets, 2, 2).geometry_hash()) << "the seed must matter";
  }
}

// Speed-ups must not change the plant. These hashes are the plants grown before the point tiers
// (commit e041b84, `growbench run -a spacecol -s SCENE --set ...`, seed 1): a change to how points are
// searched that moves any of them changed the algorithm, not only its cost. The last case has six tiers
// and rebuilds them several times.
TEST(SpaceColonization, PlantsAreThoseGrownBeforeThePointTiers) {
  const Scene envelope = load_scene("envelope"), wall = load_scene("wall");
  const SceneQuery qe(envelope), qw(wall);
  struct Case {
    const Scene* scene;
    const SceneQuery* query;
    std::vector<std::string> sets;
    const char* hash;
  };
  for (const Case& c : std::vector<Case>{
           {&envelope, &qe, {"point_count=3000"}, "dfee095c25ce8fc7"},
           {&envelope, &qe, {"venation=closed", "point_count=2000"}, "d3bf8a1eca51bfcf"},
           {&wall, &qw, {"surface=cling", "point_count=2000"}, "942bc4822577933a"},
           {&envelope,
            &qe,
            {"surface=avoid", "point_count=3000", "noise=0.3", "noise_field=random", "tropism=0,0.2,0"},
            "f18f97a11cd5ca20"},
           {&envelope, &qe, {"point_count=20000", "kill=0.02", "step=0.01"}, "d68f3d0d33164039"},
       })
    for (const int threads : {1, 2})
      EXPECT_EQ(grow("spacecol", *c.scene, *c.query, c.sets, threads).geometry_hash(), c.hash)
          << c.sets.front() << ", " << threads << " threads";
}

TEST(SpaceColonization, BadParameterCombinationsAreInputErrors) {
  const Scene s = open_space({{0, 0, 0}});
  SceneQuery q(s, {.build_sdf = false});
  EXPECT_THROW(grow("spacecol", s, q, {"kill=0.5", "influence=0.3"}), InputError);
  EXPECT_THROW(grow("spacecol", s, q, {"points=envelope"}), InputError);  // scene has no envelope
  EXPECT_THROW(grow("spacecol", s, q, {"points=file"}), InputError);      // no file named
  const std::string bad = points_file("badpts", "1 2 3\n1 2\n");
  try {
    grow("spacecol", s, q, {"points=file", "points_file=" + bad});
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("points.txt:2:"), std::string::npos) << e.what();
  }
}

// An envelope that is also a solid mesh of the scene: almost every candidate point is inside the solid, and
// the few left would grow a stalk toward nothing asked for. The run is refused and says why.
TEST(SpaceColonization, PointsInsideASolidAreRefusedNotKept) {
  Scene s = open_space({{0, -0.5f, 0}});
  s.meshes.push_back(geom::make_box("block", {-1, 0, -1}, {1, 2, 1}));
  Shape env;
  env.kind = Shape::Kind::Box;
  env.min = {-1, 0, -1};
  env.max = {1, 2, 1};
  s.envelope = env;
  const SceneQuery q(s);
  try {
    grow("spacecol", s, q, {"points=envelope", "point_count=5000"});
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("of 5000 attraction points could be placed in the envelope of scene 'space'"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("fell inside solids"), std::string::npos) << what;
  }
}

// The harness calls load_inputs() in the scene_load phase: after it, growth reads no file (this one is
// gone by then) and grows the plant that reading the file in start() grows.
TEST(SpaceColonization, PointsFileIsReadBeforeGrowth) {
  const Scene s = open_space({{0, 0, 0}});
  SceneQuery q(s, {.build_sdf = false});
  const std::string f = points_file("loaded", "-0.5 1 0\n0.5 1 0\n0 1.5 0.5\n");
  const std::vector<std::string> sets = exact(f);
  const Plant direct = grow("spacecol", s, q, sets);
  const AlgorithmEntry& e = find_algorithm("spacecol");
  Params p = default_params(e);
  for (const auto& a : sets) p.set_assignment(a);
  auto algo = e.make();
  algo->load_inputs(p);
  std::filesystem::remove(f);
  algo->start(s, q, p, 1);
  while (algo->step()) {
  }
  algo->finish();
  ASSERT_GT(direct.nodes.size(), 10u);
  EXPECT_EQ(algo->plant().geometry_hash(), direct.geometry_hash());
  // A second start() (the file read once is used once) reads the file again, which is now an error.
  EXPECT_THROW(algo->start(s, q, p, 1), InputError);
  // A file that cannot be read is an input error in load_inputs() already.
  EXPECT_THROW(e.make()->load_inputs(p), InputError);
}

}  // namespace
}  // namespace growbench
