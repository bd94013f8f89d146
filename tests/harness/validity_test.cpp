// The validity verdict (harness/output/validity.hpp): each check catches a plant planted to fail it, a real
// plant passes them all, and an algorithm's own word decides what the harness cannot see.
#include "harness/output/validity.hpp"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "harness/output/metrics.hpp"
#include "harness/run/trial.hpp"
#include "scenes/geometry.hpp"
#include "scenes/scene_library.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

// A 4 m cube of a scene (diagonal ~6.9 m): a climbable box on a non-climbable ground slab.
Scene box_scene() {
  Scene s;
  s.name = "box";
  TriangleMesh ground = geom::make_box("ground", {-2, -0.1f, -2}, {2, 0, 2});
  ground.climbable = false;
  s.meshes.push_back(std::move(ground));
  s.meshes.push_back(geom::make_box("block", {-0.5f, 0, -0.5f}, {0.5f, 2, 0.5f}));
  s.seeds.push_back({{0.6f, 0.02f, 0}, {0, 1, 0}, 0});
  return s;
}

// Nodes from `pts`, each the child of the one before (the first a root).
Plant chain(const std::vector<glm::vec3>& pts, float radius = 0.005f) {
  Plant p;
  for (std::size_t i = 0; i < pts.size(); ++i)
    p.nodes.push_back({pts[i], radius, i == 0 ? kNoParent : static_cast<std::int32_t>(i - 1), 0, 0, 0});
  return p;
}

// A real plant: a shoot up the block's side, with a branch.
Plant climber() {
  Plant p = chain({{0.6f, 0.02f, 0}, {0.55f, 0.5f, 0}, {0.52f, 1.0f, 0.1f}, {0.52f, 1.5f, 0.2f}});
  p.nodes.push_back({{0.53f, 1.2f, -0.3f}, 0.005f, 2, 1, 1, 0});
  return p;
}

Verdict judge(const Plant& p, const Scene& s, const OwnVerdict& own = {}) {
  SceneQuery q(s);
  const nlohmann::json m = compute_metrics(p, q);
  return judge_plant(p, s, &m, own);
}

// The one reason of a degenerate verdict that starts with `check`, or "" (and a message) when there is none.
std::string reason(const Verdict& v, const std::string& check) {
  for (const auto& r : v.reasons)
    if (r.rfind(check + ":", 0) == 0) return r;
  return "";
}

TEST(Validity, ARealPlantIsValid) {
  const Verdict v = judge(climber(), box_scene());
  EXPECT_EQ(v.status, "valid");
  EXPECT_TRUE(v.reasons.empty()) << v.reasons.front();
}

TEST(Validity, NothingGrew) {
  Plant p;
  p.nodes.push_back({{0.6f, 0.02f, 0}, 0.005f, kNoParent, 0, 0, 0});
  const Verdict v = judge(p, box_scene());
  EXPECT_EQ(v.status, "degenerate");
  EXPECT_EQ(reason(v, "nothing grew"), "nothing grew: 1 node and no branch");
}

TEST(Validity, Stunted) {
  // A thousand segments of 10 micrometres, going up (so not flat as well).
  std::vector<glm::vec3> pts;
  for (int i = 0; i <= 1000; ++i) pts.push_back({0.6f, 0.02f + 1e-5f * static_cast<float>(i), 0});
  const Verdict v = judge(chain(pts), box_scene());
  EXPECT_EQ(v.status, "degenerate");
  EXPECT_NE(reason(v, "stunted"), "") << v.reasons.size();
  EXPECT_EQ(reason(v, "flat"), "");
}

TEST(Validity, Flat) {
  // 4 m of branches across the ground, within 2 cm of height; 5 cm would be just over 1% of the spread too.
  const Plant p = chain({{-1.8f, 0.01f, 1}, {-0.6f, 0.02f, 1.2f}, {0.6f, 0.01f, 1}, {1.8f, 0.03f, 1.2f}});
  const Verdict v = judge(p, box_scene());
  EXPECT_EQ(v.status, "degenerate");
  EXPECT_EQ(reason(v, "flat"), "flat: 3.65 m of branches within 2 cm of height across 3.61 m");
  // Rising a tenth of its spread, the same path is a plant.
  const Plant rising = chain({{-1.8f, 0.01f, 1}, {-0.6f, 0.2f, 1.2f}, {0.6f, 0.3f, 1}, {1.8f, 0.4f, 1.2f}});
  EXPECT_EQ(reason(judge(rising, box_scene()), "flat"), "");
}

TEST(Validity, SeedsThatDidNotGrow) {
  Plant p = climber();
  for (int k = 0; k < 4; ++k)  // four more roots that never grew
    p.nodes.push_back({{-0.7f, 0.02f, -0.3f + 0.2f * static_cast<float>(k)}, 0.005f, kNoParent, 0, 0, 0});
  const Verdict v = judge(p, box_scene());
  EXPECT_EQ(reason(v, "seeds"), "seeds: 1 of 5 grew a branch");
}

TEST(Validity, InsideASolid) {
  // A shoot up the block's axis: inside it from end to end.
  const Verdict v = judge(chain({{0, 0.1f, 0}, {0, 0.6f, 0}, {0.1f, 1.1f, 0}, {0.1f, 1.6f, 0.1f}}), box_scene());
  EXPECT_EQ(v.status, "degenerate");
  EXPECT_EQ(reason(v, "inside"), "inside: 100% of the branches lie inside solids (over 50%)");
}

TEST(Validity, Folded) {
  // A thick zigzag folded onto itself: every segment lies against the ones two and more along.
  std::vector<glm::vec3> pts;
  for (int i = 0; i < 40; ++i)
    pts.push_back({1.2f + 0.1f * static_cast<float>(i % 2), 0.3f + 0.01f * static_cast<float>(i), 1.2f});
  const Verdict v = judge(chain(pts, 0.05f), box_scene());
  EXPECT_EQ(v.status, "degenerate");
  EXPECT_EQ(reason(v, "folded").rfind("folded: 100% of the segments cross another", 0), 0u) << v.reasons.front();
}

TEST(Validity, ADecalOnACardOffTheScene) {
  Scene ground_only = box_scene();
  ground_only.meshes.pop_back();  // the ground slab alone: nothing climbable
  Plant p = climber();
  p.decals.push_back({"texture.png", kPlanarDecal, {-1, 0, 1}, {2, 0, 0}, {0, 2, 0}});
  const Verdict v = judge(p, ground_only);
  EXPECT_EQ(reason(v, "off the scene"),
            "off the scene: texture.png is drawn on a card, and the scene has no climbable surface to lay it on");
  EXPECT_EQ(reason(judge(p, box_scene()), "off the scene"), "");
}

TEST(Validity, TheAlgorithmsOwnWord) {
  const Verdict own = judge(climber(), box_scene(), {"", {"attraction: none of the 10 attraction points was reached"}});
  EXPECT_EQ(own.status, "degenerate");
  EXPECT_EQ(own.reasons, std::vector<std::string>{"attraction: none of the 10 attraction points was reached"});
  // Not applicable outranks everything, with the algorithm's reason alone.
  const Verdict na = judge(Plant{}, box_scene(), {"nothing to climb", {"attraction: none"}});
  EXPECT_EQ(na.status, "not_applicable");
  EXPECT_EQ(na.reasons, std::vector<std::string>{"nothing to climb"});
}

TEST(Validity, WithoutMetricsTheShapeChecksStillRun) {
  const Plant p = chain({{-1.8f, 0.01f, 1}, {1.8f, 0.02f, 1}});
  const Verdict v = judge_plant(p, box_scene(), nullptr, {});
  EXPECT_NE(reason(v, "flat"), "");
}

// Trials record the verdict: a climber on a scene with nothing to climb is not applicable, by its word.
TEST(Validity, ATrialRecordsItsVerdict) {
  for (const char* algorithm : {"ivy", "hadrich"}) {
    TrialSpec spec;
    spec.algorithm = algorithm;
    spec.scene = "envelope";
    spec.max_steps = 5;
    const TrialRecord rec = run_trial_record(spec);
    ASSERT_TRUE(rec.results.verdict) << algorithm;
    EXPECT_EQ(rec.results.verdict->status, "not_applicable") << algorithm;
    ASSERT_EQ(rec.results.verdict->reasons.size(), 1u) << algorithm;
    EXPECT_NE(rec.results.verdict->reasons[0].find("no climbable surface"), std::string::npos)
        << rec.results.verdict->reasons[0];
    EXPECT_TRUE(rec.results.metrics->at("coverage").is_null()) << "nothing to cover is n/a, not 0";
  }
  TrialSpec spec;
  spec.algorithm = "spacecol";
  spec.scene = "wall";
  spec.params = {"point_count=1500", "surface=avoid"};
  EXPECT_EQ(run_trial_record(spec).results.verdict->status, "valid");
}

}  // namespace
}  // namespace growbench
