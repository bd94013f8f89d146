#include "algorithms/plant.hpp"

#include <gtest/gtest.h>

namespace growbench {
namespace {

Plant y_plant() {
  // 0 - 1 - 2 (main axis), 1 - 3 (lateral)
  Plant p;
  p.nodes = {{{0, 0, 0}, 0, kNoParent, 0, 0, 0},
             {{0, 1, 0}, 0, 0, 0, 0, 1},
             {{0, 2, 0}, 0, 1, 0, 0, 2},
             {{1, 2, 0}, 0, 1, 1, 1, 2}};
  return p;
}

TEST(Plant, PipeModelRadii) {
  Plant p = y_plant();
  assign_pipe_radii(p, 0.01f, 2.0f);
  EXPECT_FLOAT_EQ(p.nodes[2].radius, 0.01f);
  EXPECT_FLOAT_EQ(p.nodes[3].radius, 0.01f);
  EXPECT_NEAR(p.nodes[1].radius, 0.01f * std::sqrt(2.0f), 1e-7f);  // r^2 = r2^2 + r3^2
  EXPECT_NEAR(p.nodes[0].radius, p.nodes[1].radius, 1e-7f);
  assign_pipe_radii(p, 0.01f, 3.0f);
  EXPECT_NEAR(p.nodes[1].radius, 0.01f * std::cbrt(2.0f), 1e-7f);
}

TEST(Plant, LengthHashAndValidation) {
  Plant p = y_plant();
  EXPECT_NEAR(p.total_length(), 2.0 + std::sqrt(2.0), 1e-6);
  EXPECT_EQ(p.validate(), "");
  const std::string h = p.geometry_hash();
  EXPECT_EQ(h, y_plant().geometry_hash());
  p.nodes[3].position.x = std::nextafter(1.0f, 2.0f);  // one ulp changes the hash
  EXPECT_NE(p.geometry_hash(), h);
  p.nodes[3].parent = 3;
  EXPECT_NE(p.validate().find("node 3"), std::string::npos);
  Plant q = y_plant();
  q.nodes[2].position.y = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(q.validate(), "node 2 lies at (0, nan, 0), not within 1e+09 m of the origin");
  // Finite but beyond the scene's bounds: Embree aborted the process on rays from there.
  q.nodes[2].position.y = 2e18f;
  EXPECT_EQ(q.validate(), "node 2 lies at (0, 2e+18, 0), not within 1e+09 m of the origin");
  q = y_plant();
  q.polygons.push_back({{{0, 0, 0}, {1, 0, 0}, {0, std::numeric_limits<float>::quiet_NaN(), 0}}});
  EXPECT_EQ(q.validate(), "polygon 0 vertex 2 lies at (0, nan, 0), not within 1e+09 m of the origin");
  q = y_plant();
  q.node_attributes.push_back({"Cd", 1, std::vector<float>(q.nodes.size(), 0.5f)});
  EXPECT_EQ(q.validate(), "");
  q.node_attributes[0].values[1] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(q.validate(), "attribute 'Cd' has the non-finite value inf at 1");
  Plant r = y_plant();
  r.organs.push_back({{0, 0, 0}, {1, 0, 0, 0}, 0.1f, OrganKind::Leaf, 9});
  EXPECT_NE(r.validate().find("organ 0"), std::string::npos);
  // An organ's orientation is a rotation: a quaternion of another length, or NaN, is refused.
  Plant s = y_plant();
  s.organs.push_back({{0, 0, 0}, {1, 0, 0, 0}, 0.1f, OrganKind::Leaf, 1});
  EXPECT_EQ(s.validate(), "");
  s.organs[0].orientation = glm::quat(2.0f, 0.0f, 0.0f, 0.0f);
  EXPECT_EQ(s.validate(), "organ 0 has orientation (w 2, x 0, y 0, z 0), not a unit quaternion");
  s.organs[0].orientation = glm::quat(0.0f, 0.0f, 0.0f, 0.0f);
  EXPECT_NE(s.validate().find("not a unit quaternion"), std::string::npos);
  s.organs[0].orientation.y = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(s.validate().find("not a unit quaternion"), std::string::npos);
}

TEST(Plant, OptionalDataEntersTheHashOnlyWhenPresent) {
  Plant p = y_plant();
  const std::string h = p.geometry_hash();
  EXPECT_EQ(h, "4c837999314598b7");  // as before the prefix, tubes and geometry type existed (commit 1d14bd5)
  p.group_prefix = "lsys";           // names no group: the plant is the same
  EXPECT_EQ(p.geometry_hash(), h);
  p.node_tubes.assign(4, TubeShape{});
  EXPECT_EQ(p.validate(), "");
  EXPECT_NE(p.geometry_hash(), h);
  p.node_tubes[2] = {3, 5};
  const std::string tubes = p.geometry_hash();
  p.node_tubes[2].divisions = 6;
  EXPECT_NE(p.geometry_hash(), tubes);
  p.node_tubes[2].divisions = 2;
  EXPECT_NE(p.validate().find("node 2 has 2 tube divisions"), std::string::npos) << p.validate();
  p.node_tubes[2] = {65, 0};
  EXPECT_NE(p.validate().find("node 2 has 65 tube sections"), std::string::npos) << p.validate();
  p.node_tubes.resize(3);
  EXPECT_NE(p.validate().find("3 node tubes for 4 nodes"), std::string::npos) << p.validate();
  Plant g = y_plant();
  g.branch_geometry = BranchGeometry::Skeleton;
  EXPECT_NE(g.geometry_hash(), h);
  g.node_groups = {0, 0, 1, -1};
  g.group_prefix = "a b";
  EXPECT_NE(g.validate().find("group prefix 'a b'"), std::string::npos) << g.validate();
  g.group_prefix = "twig";
  EXPECT_EQ(g.validate(), "");
  EXPECT_EQ(g.group_name(3), "twig3");
  const std::string named = g.geometry_hash();
  g.group_prefix = "branch";
  EXPECT_NE(g.geometry_hash(), named);
  g.group_prefix.clear();
  EXPECT_EQ(g.group_name(0), "group0");
}

}  // namespace
}  // namespace growbench
