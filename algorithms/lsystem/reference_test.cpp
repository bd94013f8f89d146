// The Houdini L-system reference's semantics where growbench once read it otherwise: T(g) bends toward -Y
// and never past it (in radians or degrees), ~(a) turns the heading by at most a, % removes the rest of its branch from
// the string, rand() differs between the plants of one scene, and a grammar file's settings are what the record keeps.
#include <cmath>
#include <filesystem>
#include <numbers>
#include <set>

#include <gtest/gtest.h>
#include <stb_image_write.h>

#include "algorithms/grow_util.hpp"
#include "algorithms/lsystem/lsystem.hpp"
#include "algorithms/organ_shapes.hpp"
#include "core/errors.hpp"
#include "core/file_hash.hpp"
#include "harness/record/record.hpp"
#include "harness/run/trial.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

struct Open {
  Scene scene = load_scene("envelope");
  SceneQuery query{scene};
};

Open& open_scene() {
  static Open o;
  return o;
}

Plant draw(const std::string& premise, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> sets = {"premise=" + premise, "rules=", "generations=0", "step_size=1"};
  sets.insert(sets.end(), extra.begin(), extra.end());
  return test::grow("lsystem", open_scene().scene, open_scene().query, sets);
}

glm::dvec3 segment(const Plant& p, std::size_t node) {
  const auto& n = p.nodes[node];
  return glm::normalize(glm::dvec3(n.position) - glm::dvec3(p.nodes[static_cast<std::size_t>(n.parent)].position));
}

std::string derive(const std::string& premise, const std::string& rules, double generations) {
  Params p = default_params(find_algorithm("lsystem"));
  p.set("premise", premise);
  p.set("rules", rules);
  p.set("generations", std::to_string(generations));
  return derive_lsystem(p, 1, nullptr, nullptr, 0).text;
}

}  // namespace

// T(g) turns the heading toward -Y by g |H x -Y| radians (ABOP's tropism), but never past straight down: from
// horizontal, T(5) hangs the next segment straight down where it once swung on past it to (0.284, 0.959, 0).
TEST(LSystemReference, GravityBendsTowardDownAndNeverPastIt) {
  const Plant hang = draw("FF+(90)FT(5)F");
  ASSERT_EQ(hang.nodes.size(), 5u);
  EXPECT_NEAR(std::abs(segment(hang, 3).y), 0.0, 1e-9);  // horizontal before T
  const glm::dvec3 down = segment(hang, 4);
  EXPECT_NEAR(down.y, -1.0, 1e-6) << down.x << " " << down.y << " " << down.z;
  // A small g bends by g |H x -Y|: from horizontal, 0.5 rad below it.
  const glm::dvec3 bent = segment(draw("FF+(90)FT(0.5)F"), 4);
  EXPECT_NEAR(bent.y, -std::sin(0.5), 1e-6);
  // Again and again it stays down; a negative g lifts it, at most to straight up.
  EXPECT_NEAR(segment(draw("FF+(90)FT(5)FT(5)FT(5)F"), 6).y, -1.0, 1e-6);
  EXPECT_NEAR(segment(draw("FF+(90)FT(-5)F"), 4).y, 1.0, 1e-6);
}

// gravity_units=degrees reads T's amount as an angle, as every other turtle angle: from horizontal, T(5)
// bends the next segment 5 degrees down rather than hanging it. The gravity parameter, T's default, too.
TEST(LSystemReference, GravityInDegreesBendsByThatAngle) {
  const double five = 5.0 * std::numbers::pi / 180.0;
  EXPECT_NEAR(segment(draw("FF+(90)FT(5)F", {"gravity_units=degrees"}), 4).y, -std::sin(five), 1e-6);
  EXPECT_NEAR(segment(draw("FF+(90)FTF", {"gravity_units=degrees", "gravity=5"}), 4).y, -std::sin(five), 1e-6);
  EXPECT_NEAR(segment(draw("FF+(90)FTF", {"gravity=0.5"}), 4).y, -std::sin(0.5), 1e-6);
}

// ~(a) draws a heading within a degrees of the current one: over many draws none turns further, and they
// reach close to a (three turns of up to a each could move it up to about 1.7 a).
TEST(LSystemReference, RandomTurnMovesTheHeadingAtMostItsAngle) {
  std::string premise;
  for (int i = 0; i < 600; ++i) premise += "[~(10)F]";
  const Plant p = draw(premise);
  double most = 0.0;
  std::size_t segments = 0;
  for (std::size_t i = 0; i < p.nodes.size(); ++i) {
    if (p.nodes[i].parent < 0) continue;
    ++segments;
    const double deg = std::acos(std::clamp(segment(p, i).y, -1.0, 1.0)) * 180.0 / std::numbers::pi;
    EXPECT_LE(deg, 10.0 + 1e-6) << i;
    most = std::max(most, deg);
  }
  EXPECT_EQ(segments, 600u);
  EXPECT_GT(most, 9.0);
}

// % cuts off the rest of its branch in the string itself, so the cut part no longer grows.
TEST(LSystemReference, CutRemovesTheRestOfItsBranchFromTheString) {
  EXPECT_EQ(derive("FA%B", "B = BB", 20), "FA%");
  EXPECT_EQ(derive("F[A%BB[C]D]C", "C = CC", 2), "F[A%]CCCC");
  EXPECT_EQ(derive("A", "A = F[+A%B]A\nB = BB", 2), "F[+F[+A%]A%]F[+A%]A");
}

// rand() gives each plant of a multi-seed scene its own values, as ~ and probabilities do.
TEST(LSystemReference, RandDiffersBetweenThePlantsOfAScene) {
  const Scene wall = load_scene("wall");
  ASSERT_GE(wall.seeds.size(), 3u);
  const SceneQuery q(wall);
  const Plant p = test::grow("lsystem", wall, q, {"premise=A", "rules=A = F(0.05 + 0.1 * rand(i))A", "generations=4"});
  std::vector<std::vector<float>> lengths(wall.seeds.size());
  for (std::size_t i = 0; i < p.nodes.size(); ++i)
    if (p.nodes[i].parent >= 0)
      lengths[p.nodes[i].shoot].push_back(static_cast<float>(
          glm::length(p.nodes[i].position - p.nodes[static_cast<std::size_t>(p.nodes[i].parent)].position)));
  std::set<std::vector<float>> distinct(lengths.begin(), lengths.end());
  EXPECT_EQ(distinct.size(), wall.seeds.size());
}

// What a grammar file sets is what the record keeps as the parameters, with the file's content hash; a
// setting given twice is an error at its second line.
TEST(LSystemReference, TheRecordKeepsWhatTheGrammarFileSet) {
  const auto dir = test::temp_dir("lsys_record");
  const std::string grammar = test::write_text(dir / "g.lsys", "premise: FF\nangle: 33\ngenerations: 0\n");
  TrialSpec spec;
  spec.algorithm = "lsystem";
  spec.scene = "envelope";
  spec.params = {"grammar=" + grammar};
  spec.metrics = false;
  const TrialRecord r = run_trial_record(spec);
  EXPECT_EQ(r.results.params.at("premise"), "FF");
  EXPECT_EQ(r.results.params.at("angle"), 33.0);
  EXPECT_EQ(r.results.params.at("generations"), 0.0);
  ASSERT_EQ(r.results.inputs.size(), 1u);
  EXPECT_EQ(r.results.inputs[0].param, "grammar");
  EXPECT_EQ(r.results.inputs[0].hash, file_hash(grammar));
  spec.params.push_back("angle=40");  // the user's --set stays above the file
  EXPECT_EQ(run_trial_record(spec).results.params.at("angle"), 40.0);

  const std::string twice = test::write_text(dir / "twice.lsys", "premise: FF\nangle: 33\n# again\nangle: 20\n");
  spec.params = {"grammar=" + twice};
  EXPECT_EQ(test::error_of([&] { run_trial_record(spec); }),
            twice + ":4:1: 'angle' is set twice (first at line 2); expected each setting once");

  // A rule with a multi-letter predecessor reads as a setting; the error says what a rule's predecessor is.
  const std::string two = test::write_text(dir / "two.lsys", "premise: A\nAB = F\n");
  spec.params = {"grammar=" + two};
  EXPECT_NE(test::error_of([&] {
              run_trial_record(spec);
            }).find(two + ":2:1: unknown setting 'AB'; if this is a rule, its predecessor is one symbol"),
            std::string::npos);
}

// The fine-stemmed cherry (examples/cherry-fine-stems.lsys): five organs and three leaves of a cluster on
// pedicels 0.01 to 0.03 long and up to 0.035 wide, all leaving one joint, hung together by T. As grown,
// its leaves pass through each other; avoid placement keeps most organs (their bases in the joint's
// collar, fanned out along their pedicels where they meet), and no kept leaves overlap. It kept 22 of 281
// while the joint's other pedicels blocked every organ's base.
TEST(LSystemReference, AvoidPlacementKeepsMostOrgansOfAFineStemmedCherry) {
  TrialSpec spec;
  spec.algorithm = "lsystem";
  spec.scene = "wall";
  spec.params = {"grammar=cherry-fine-stems", "surface=avoid"};
  spec.organs = {"placement=free"};
  const TrialRecord free = run_trial_record(spec);
  ASSERT_TRUE(free.results.organs.has_value());
  const std::uint64_t grown = free.results.organs->placed;
  EXPECT_GT(grown, 200u);
  EXPECT_GT(free.results.metrics->at("leaf_overlap").get<double>(), 0.1);
  spec.organs = {"placement=avoid"};
  const TrialRecord avoid = run_trial_record(spec);
  ASSERT_TRUE(avoid.results.organs.has_value());
  const OrganPassRecord& o = *avoid.results.organs;
  EXPECT_EQ(o.placed + o.fallen_back + o.dropped, grown);
  for (const auto& [kind, c] : o.by_kind) {
    SCOPED_TRACE(kind);
    // Most of each kind stay: four in five, as grown, turned, smaller or as a fallback.
    EXPECT_GE(5 * (c.placed + c.fallen_back), 4 * (c.placed + c.fallen_back + c.dropped))
        << c.placed << " placed, " << c.fallen_back << " fallen back, " << c.dropped << " dropped";
  }
  EXPECT_EQ(avoid.results.metrics->at("leaf_overlap").get<double>(), 0.0);
}

// A command that takes a number followed by digits ('/30') reads as the command and the digits as
// symbols of their own, as the reference's syntax says; it was silent. The record now keeps a warning naming the line
// and column, with the argument form, unless a rule rewrites those digits (then they are meant as symbols).
TEST(LSystemReference, ABareNumberAfterATurnIsAWarningUnlessTheDigitsAreSymbols) {
  TrialSpec spec;
  spec.algorithm = "lsystem";
  spec.scene = "envelope";
  spec.metrics = false;
  spec.params = {"premise=A", "rules=A = F/30A\nB = +5.5F?2", "generations=2"};
  const TrialRecord r = run_trial_record(spec);
  ASSERT_EQ(r.results.warnings.size(), 3u);
  EXPECT_EQ(r.results.warnings[2].substr(0, 40), "parameter 'rules':2:10: '?2' reads as '?");
  EXPECT_EQ(r.results.warnings[0],
            "parameter 'rules':1:6: '/30' reads as '/' followed by the symbols '3', '0'; if 30 is its argument, "
            "write '/(30)'");
  EXPECT_EQ(r.results.warnings[1].substr(0, 42), "parameter 'rules':2:5: '+5.5' reads as '+'");
  spec.params = {"premise=A", "rules=A = F/30A\n3 = F", "generations=2"};
  EXPECT_TRUE(run_trial_record(spec).results.warnings.empty());
  spec.params = {"premise=A", "rules=A = F/(30)A", "generations=2"};
  EXPECT_TRUE(run_trial_record(spec).results.warnings.empty());
  // A trial that fails has no record: its error carries the warnings, which may say why it failed.
  spec.params = {"premise=A", "rules=A = AA/30", "generations=30", "max_symbols=1000"};
  const std::string e = test::error_of([&] { run_trial_record(spec); });
  EXPECT_NE(e.find("L-system runaway"), std::string::npos) << e;
  EXPECT_NE(e.find("\n  warning: parameter 'rules':1:7: '/30' reads as '/'"), std::string::npos) << e;
}

// Houdini's Point Attributes: gen is the rewrite that made the module drawing a node (it was the branch
// order, and lage and up were missing). FA with A = FA, two rewrites, draws FFF from the premise's F and
// those rewrites 1 and 2 made; lage counts vertical_increment per segment; up is the turtle's, unit and
// across the heading, and turns with a pitch.
TEST(LSystemReference, PointAttributesGiveUpLageAndTheGenerationThatMadeEachNode) {
  const Plant p = draw("FA", {"rules=A = F&(90)A", "generations=2", "point_attributes=true", "vertical_increment=0.5"});
  auto attr = [&](const std::string& name) {
    const auto it = std::find_if(p.node_attributes.begin(), p.node_attributes.end(),
                                 [&](const NodeAttribute& a) { return a.name == name; });
    EXPECT_NE(it, p.node_attributes.end()) << name;
    return it == p.node_attributes.end() ? std::vector<float>{} : it->values;
  };
  ASSERT_EQ(p.nodes.size(), 4u);  // the root and three segments
  EXPECT_EQ(attr("gen"), (std::vector<float>{0, 0, 1, 2}));
  EXPECT_EQ(attr("lage"), (std::vector<float>{0, 0.5f, 1.0f, 1.5f}));
  const std::vector<float> up = attr("up");
  ASSERT_EQ(up.size(), 12u);
  for (std::size_t n = 1; n < 4; ++n) {
    const glm::vec3 u(up[3 * n], up[3 * n + 1], up[3 * n + 2]);
    const glm::vec3 h = glm::normalize(p.nodes[n].position - p.nodes[n - 1].position);
    EXPECT_NEAR(glm::length(u), 1.0f, 1e-5f) << n;
    EXPECT_NEAR(glm::dot(u, h), 0.0f, 1e-5f) << n;
  }
  // the pitch between the second and third segments turned the up vector
  EXPECT_LT(std::abs(up[6] * up[9] + up[7] * up[10] + up[8] * up[11]), 0.5f);
  // Without the flag there are none of them.
  const Plant plain = draw("FA", {"rules=A = F&(90)A", "generations=2"});
  EXPECT_TRUE(plain.node_attributes.empty());
  EXPECT_NE(test::error_of([] {
              draw("a(\"up\", 1, 0, 0)FA", {"rules=A = FA", "generations=1", "point_attributes=true"});
            }).find("point_attributes: the grammar sets 'up' itself"),
            std::string::npos);
}

// chan() read constants only; Houdini's channels are animated. A channel's keys generation:value are read
// at the generation being made, linear between keys and held beyond them: the segments made by
// rewrites 1, 2 and 3 under keys 1:1 3:3 are 1, 2 and 3 long, and 5 beyond the last key.
TEST(LSystemReference, AnimatedChannelsAreReadAtTheGenerationBeingMade) {
  const Plant p = draw("A", {"rules=A = F(chan(1))A", "generations=4", "channels=0.5, 1:1 3:3 4:5"});
  std::vector<float> ys;
  for (const auto& n : p.nodes) ys.push_back(n.position.y);
  EXPECT_EQ(ys, (std::vector<float>{0, 1, 3, 6, 11}));
  EXPECT_EQ(draw("A", {"rules=A = F(chan(1))A", "generations=2", "channels=0.5, 1:1 3:3"}).nodes.back().position.y,
            3.0f);
  EXPECT_EQ(draw("A", {"rules=A = F(chan(0))", "generations=1", "channels=0.25"}).nodes.back().position.y, 0.25f);
  EXPECT_EQ(test::error_of([] {
              draw("A", {"rules=A = F(chan(0))", "generations=1", "channels=2:1 1:0"});
            }),
            "channels: in '2:1 1:0', the generations of the keys must increase");
  EXPECT_EQ(test::error_of([] {
              draw("A", {"rules=A = F(chan(0))", "generations=1", "channels=1 2"});
            }),
            "channels: in '1 2', expected one number or keys generation:value");
  EXPECT_EQ(test::error_of([] {
              draw("A", {"rules=A = F(chan(0))", "generations=1", "channels=1:x"});
            }),
            "channels: in '1:x', expected a number, found 'x'");
  EXPECT_EQ(test::error_of([] {
              draw("A", {"rules=A = F(chan(0))", "generations=1", "channels=1,,2"});
            }),
            "channels: channel 1 is empty; expected a number or keys generation:value");
  // a space after a key's colon is read as written without one
  EXPECT_EQ(draw("A", {"rules=A = F(chan(0))A", "generations=2", "channels=1: 1 3: 3"}).nodes.back().position.y, 3.0f);
}

// J/K/M's stamps set the settings of their shape that leaf_param_a/b/c name (Houdini's Leaf Params), as a
// stamped input geometry does: J(s,0,6) with leaf_param_a=petals draws a six-petalled blossom. A module
// without the stamp keeps the plain shape; a setting the shape lacks, or an OBJ shape, is an error.
TEST(LSystemReference, StampsSetTheShapeSettingsTheLeafParamsName) {
  const Plant p = draw("FJ(0.1,0,6)FJ(0.1,0,8)FJ(0.1,0,6)FJ(0.1)",
                       {"kind_j=flower", "leaf_param_a=petals", "organ_j=blossom:cup=20"});
  ASSERT_EQ(p.organs.size(), 4u);
  const auto name = [&](const Organ& o) {
    return o.shape == kKindShape ? std::string("(kind)") : p.organ_shapes.at(o.shape);
  };
  EXPECT_EQ(name(p.organs[0]), "blossom:cup=20,petals=6");
  EXPECT_EQ(name(p.organs[1]), "blossom:cup=20,petals=8");
  EXPECT_EQ(p.organs[2].shape, p.organs[0].shape);
  EXPECT_EQ(name(p.organs[3]), "blossom:cup=20");
  EXPECT_EQ(p.organs[0].stamp[0], 6.0f);
  const OrganShapes shapes(p);
  EXPECT_NE(shapes.of(p.organs[0]).mesh.triangles.size(), shapes.of(p.organs[1]).mesh.triangles.size());
  // Without organ_j, the kind's own shape is stamped.
  EXPECT_EQ(draw("FJ(0.1,0,0.5)", {"leaf_param_a=width"}).organ_shapes.back(), "leaf:width=0.5");

  EXPECT_NE(test::error_of([&] { draw("FJ(0.1,0,3)", {"leaf_param_a=colour"}); }).find("J's stamps"),
            std::string::npos);
  const std::string obj = std::string(GROWBENCH_SOURCE_DIR) + "/scenes/meshes/uv-cube.obj";
  EXPECT_NE(test::error_of([&] {
              draw("FJ(0.1,0,3)", {"leaf_param_a=width", "organ_j=" + obj});
            }).find("is the OBJ file '" + obj + "', which has no settings"),
            std::string::npos);
}

// Apply Color: every node's Cd is color_image's pixel at the turtle's (u, v), linearised; ' moves u.
TEST(LSystemReference, ApplyColorReadsTheImageAtTheTurtlesUv) {
  const auto dir = test::temp_dir("lsys_color");
  const std::string png = (dir / "two.png").string();
  const unsigned char px[8] = {255, 0, 0, 255, 0, 0, 255, 255};  // red, then blue
  ASSERT_NE(stbi_write_png(png.c_str(), 2, 1, 4, px, 8), 0);
  const Plant p = draw("F'(0.6)F", {"apply_color=true", "color_image=" + png});
  ASSERT_EQ(p.nodes.size(), 3u);
  ASSERT_EQ(p.node_attributes.size(), 1u);
  const NodeAttribute& cd = p.node_attributes[0];
  EXPECT_EQ(cd.name, "Cd");
  EXPECT_EQ(cd.values, (std::vector<float>{1, 0, 0, 1, 0, 0, 0, 0, 1}));  // red at u 0, blue at u 0.6
  EXPECT_EQ(test::error_of([&] { draw("F", {"apply_color=true"}); }),
            "apply_color: needs an image to read the colours from: set color_image=FILE");
  EXPECT_NE(test::error_of([&] {
              draw("a(\"Cd\",1,0,0)F", {"apply_color=true", "color_image=" + png});
            }).find("use one or the other"),
            std::string::npos);
}

}  // namespace growbench
