#include <fmt/format.h>
#include <gtest/gtest.h>

#include "scenes/scene_library.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

using test::error_of;

TEST(StandardScenes, AllBuildWithClosedSolidsSeedsAndStableHashes) {
  ASSERT_EQ(standard_scenes().size(), 8u);
  for (const auto& st : standard_scenes()) {
    const Scene s = load_scene(st.name);
    EXPECT_EQ(s.name, st.name);
    EXPECT_FALSE(s.seeds.empty()) << st.name;
    EXPECT_FALSE(s.meshes.empty()) << st.name;
    for (const auto& m : s.meshes) EXPECT_TRUE(m.is_closed()) << st.name << "/" << m.name;
    EXPECT_EQ(s.content_hash(), load_scene(st.name).content_hash()) << st.name;
    EXPECT_EQ(s.content_hash().size(), 16u);
  }
  EXPECT_NE(load_scene("wall").content_hash(), load_scene("wall", {"width=4"}).content_hash());
  EXPECT_NE(load_scene("wall").content_hash(), load_scene("column").content_hash());
}

TEST(StandardScenes, ParametersAreValidated) {
  EXPECT_NE(error_of([] { load_scene("wall", {"widht=2"}); }).find("did you mean 'width'"), std::string::npos);
  EXPECT_NE(error_of([] { load_scene("wall", {"width=-2"}); }).find("out of range"), std::string::npos);
  const std::string e = error_of([] { load_scene("wal"); });
  EXPECT_NE(e.find("unknown scene 'wal'"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'wall'"), std::string::npos) << e;
  EXPECT_NE(e.find("envelope"), std::string::npos) << e;  // lists the valid ones
}

TEST(MeshScene, FittedToStandardSizeOnAGroundWithSeedAtTheFootOfItsLitSide) {
  const Scene s = load_scene("mesh:stanford-bunny");
  const Aabb b = s.meshes[0].bounds();
  const glm::vec3 e = b.size();
  EXPECT_NEAR(std::max({e.x, e.y, e.z}), 2.0f, 1e-4f);
  EXPECT_NEAR(b.min.y, 0.0f, 1e-5f);
  // The scan's 69,451 triangles and the patches that seal its five holes (load_scene_obj).
  EXPECT_EQ(load_obj(mesh_path("stanford-bunny")).triangles.size(), 69451u);
  EXPECT_GT(s.meshes[0].triangles.size(), 69451u);
  EXPECT_TRUE(s.meshes[0].is_closed());
  // A ground slab, not climbable, its top at the mesh's lowest point.
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_FALSE(s.meshes[1].climbable);
  EXPECT_NEAR(s.meshes[1].bounds().max.y, 0.0f, 1e-6f);
  EXPECT_EQ(load_scene("mesh:stanford-bunny", {"ground=false"}).meshes.size(), 1u);
  // The seed: the lowest vertex among those whose (area-weighted) normal is within 60 degrees of
  // horizontal and faces the light, growing up along the surface.
  ASSERT_EQ(s.seeds.size(), 1u);
  const TriangleMesh& m = s.meshes[0];
  std::vector<glm::vec3> normal(m.vertices.size(), glm::vec3(0.0f));
  for (const auto& t : m.triangles)
    for (const auto k : {t.x, t.y, t.z})
      normal[k] += glm::cross(m.vertices[t.y] - m.vertices[t.x], m.vertices[t.z] - m.vertices[t.x]);
  const glm::vec3 light = s.light.towards(b.center());
  float lowest = INFINITY;
  std::size_t at = 0;
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    const float len = glm::length(normal[i]);
    if (len > 0.0f && std::abs(normal[i].y) <= 0.5f * len && glm::dot(normal[i], light) > 0.0f &&
        m.vertices[i].y < lowest) {
      lowest = m.vertices[i].y;
      at = i;
    }
  }
  EXPECT_EQ(s.seeds[0].position, m.vertices[at]);
  EXPECT_LT(s.seeds[0].position.y, 0.05f);  // at the foot, not up the side
  const glm::vec3 n = glm::normalize(normal[at]);
  EXPECT_NEAR(glm::dot(s.seeds[0].direction, n), 0.0f, 1e-5f);  // along the surface
  EXPECT_GT(s.seeds[0].direction.y, 0.9f);                      // and up
  EXPECT_NEAR(glm::length(s.seeds[0].direction), 1.0f, 1e-5f);
  const Scene raw = load_scene("mesh:stanford-bunny", {"size=0"});
  EXPECT_NEAR(raw.meshes[0].bounds().max.y, 0.187321f, 1e-5f);  // the file's own units
}

TEST(MeshScene, BundledMeshesByNameAreTheRepositorysFiles) {
  EXPECT_EQ(bundled_meshes(),
            (std::vector<std::string>{"cow", "spot", "stanford-bunny", "suzanne", "teapot", "uv-cube"}));
  const std::string file = std::string(GROWBENCH_SOURCE_DIR) + "/scenes/meshes/suzanne.obj";
  EXPECT_EQ(mesh_path("suzanne"), file);
  EXPECT_EQ(mesh_path("./suzanne"), "./suzanne");  // a path stays a path
  EXPECT_EQ(mesh_path("suzanne.obj"), "suzanne.obj");
  const Scene named = load_scene("mesh:suzanne");
  EXPECT_EQ(named.name, "suzanne");
  EXPECT_EQ(named.source, "mesh:suzanne");
  EXPECT_EQ(named.content_hash(), load_scene("mesh:" + file).content_hash());
  const std::string e = error_of([] { load_scene("mesh:suzane"); });
  EXPECT_NE(e.find("unknown mesh 'suzane' (did you mean 'suzanne'?)"), std::string::npos) << e;
  EXPECT_NE(e.find("cow, spot, stanford-bunny, suzanne, teapot"), std::string::npos) << e;
  // A scene file names them the same way, as its base or as a mesh's obj.
  const auto dir = test::temp_dir("bundled");
  const std::string based = test::write_text(dir / "s.json", R"({"schema_version": 1, "base": "mesh:suzanne",
      "meshes": [{"name": "cow", "obj": "cow"}]})");
  const Scene s = load_scene(based);
  ASSERT_EQ(s.meshes.size(), 3u);  // suzanne, its ground, the cow
  EXPECT_EQ(s.meshes[2].triangles.size(), load_obj(mesh_path("cow")).triangles.size());
  const std::string bad = test::write_text(dir / "bad.json", R"({"schema_version": 1, "base": "wall",
      "meshes": [{"name": "x", "obj": "cwo"}]})");
  const std::string e2 = error_of([&] { load_scene(bad); });
  EXPECT_NE(e2.find("/meshes/0/obj"), std::string::npos) << e2;
  EXPECT_NE(e2.find("unknown mesh 'cwo' (did you mean 'cow'?)"), std::string::npos) << e2;
}

TEST(MeshScene, BadFilesGiveClearErrors) {
  const auto dir = test::temp_dir("meshio");
  std::string e = error_of([&] { load_scene("mesh:" + (dir / "missing.obj").string()); });
  EXPECT_NE(e.find("missing.obj: no such file"), std::string::npos) << e;
  const std::string too_long = (dir / std::string(300, 'a') / "x.obj").string();  // a fuzzing finding
  e = error_of([&] { load_scene("mesh:" + too_long); });
  EXPECT_NE(e.find(too_long + ": File name too long (expected an OBJ file)"), std::string::npos) << e;
  const std::string empty = test::write_text(dir / "empty.obj", "# nothing\nv 0 0 0\n");
  e = error_of([&] { load_scene("mesh:" + empty); });
  EXPECT_NE(e.find("no faces"), std::string::npos) << e;
  const std::string bad = test::write_text(dir / "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  e = error_of([&] { load_scene("mesh:" + bad); });
  EXPECT_NE(e.find("bad.obj"), std::string::npos) << e;
  // Faces of no area (collinear or coincident corners) grew a 2-node plant on nothing, with exit 0.
  for (const char* text : {"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n"}) {
    const std::string flat = test::write_text(dir / "flat.obj", text);
    e = error_of([&] { load_scene("mesh:" + flat); });
    EXPECT_NE(e.find(flat + ": every face has zero area"), std::string::npos) << e;
  }
}

TEST(JsonScene, LoadsMeshesSeedsLightEnvelopeZonesCamera) {
  const auto dir = test::temp_dir("jsonscene");
  const std::string f = test::write_text(dir / "s.json", R"({
    "schema_version": 1, "name": "mine",
    "meshes": [{"name": "block", "box": {"min": [-1, 0, -1], "max": [1, 2, 1]}},
               {"name": "pole", "cylinder": {"base": [3, 0, 0], "top": [3, 2, 0], "radius": 0.1},
                "transform": {"translate": [0, 0, 1]}, "climbable": false, "visible": false}],
    "seeds": [{"position": [0, 0, 1.1], "direction": [0, 2, 0], "start_step": 3}],
    "light": {"type": "point", "position": [0, 5, 5]},
    "envelope": {"type": "sphere", "center": [0, 1, 0], "radius": [2, 1, 2]},
    "zones": [{"kind": "exclude", "shape": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}}],
    "camera": {"position": [0, 1, 6], "look_at": [0, 1, 0], "fov_deg": 40}
  })");
  const Scene s = load_scene(f);
  EXPECT_EQ(s.name, "mine");
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_FALSE(s.meshes[1].climbable);
  EXPECT_TRUE(s.meshes[0].visible);
  EXPECT_FALSE(s.meshes[1].visible);
  Scene shown = s;
  shown.meshes[1].visible = true;
  EXPECT_NE(shown.content_hash(), s.content_hash()) << "a collision-only mesh is part of the scene's content";
  EXPECT_NEAR(s.meshes[1].bounds().center().z, 1.0f, 1e-5f);
  ASSERT_EQ(s.seeds.size(), 1u);
  EXPECT_EQ(s.seeds[0].start_step, 3);
  EXPECT_NEAR(s.seeds[0].direction.y, 1.0f, 1e-6f);
  EXPECT_EQ(s.light.kind, Light::Kind::Point);
  ASSERT_TRUE(s.envelope);
  EXPECT_EQ(s.envelope->radii, glm::vec3(2, 1, 2));
  ASSERT_EQ(s.zones.size(), 1u);
  EXPECT_EQ(s.zones[0].kind, Zone::Kind::Exclude);
  EXPECT_EQ(s.camera.fov_deg, 40.0f);

  const std::string based =
      test::write_text(dir / "b.json", R"({"schema_version": 1, "base": "wall", "base_params": {"width": 4}})");
  EXPECT_EQ(load_scene(based).content_hash().size(), 16u);
  EXPECT_NEAR(load_scene(based).meshes[1].bounds().size().x, 4.0f, 1e-5f);
}

TEST(JsonScene, ErrorsNameFileAndJsonPath) {
  const auto dir = test::temp_dir("jsonerr");
  struct Case {
    const char* text;
    const char* expect;
  } cases[] = {
      {R"({"schema_version": 2, "meshes": []})", "at /schema_version: expected 1"},
      {R"({"schema_version": 1, "meshes": [{"box": {"min": [0,0,0], "max": [1,"a",1]}}], "seeds": [{"position": [0,0,0]}]})",
       "at /meshes/0/box/max/1: expected a number"},
      {R"({"schema_version": 1, "meshes": [{"bx": {}}]})", "at /meshes/0/bx: unknown key 'bx' (did you mean 'box'?)"},
      {R"({"schema_version": 1, "meshes": [{"box": {"min": [0,0,0], "max": [1,1,1]}, "visible": 0}]})",
       "at /meshes/0/visible: expected true or false"},
      {R"({"schema_version": 1, "meshes": [{"box": {"min": [0,0,0], "max": [1,1,1]}}]})",
       "at /seeds: a scene needs at least one seed"},
      {R"({"schema_version": 1, "meshes": [{"box": {"min": [0,0,0], "max": [1,1,1]}}], "seeds": [{"position": [0,0,0]}],
          "light": {"type": "moon"}})",
       "at /light/type: unknown light type 'moon'"},
      {R"({"schema_version": 1, "meshes": [{"obj": "nope.obj"}]})", "at /meshes/0/obj:"},
      {"{\n  \"schema_version\": 1,\n  \"meshes\": [,]\n}", "s.json:3:"},
      // Coordinates beyond kMaxCoordinate: Embree aborted on rays from a seed at 1e19 or to a light at 1e30.
      {R"({"schema_version": 1, "base": "wall", "seeds": [{"position": [0, 1e19, 0]}]})",
       "at /seeds/0/position/1: expected a number in [-1000000000, 1000000000], got 1e+19"},
      {R"({"schema_version": 1, "base": "wall", "light": {"type": "point", "position": [0, 1e30, 0]}})",
       "at /light/position/1: expected a number in [-1000000000, 1000000000]"},
      {R"({"schema_version": 1, "meshes": [{"box": {"min": [0,0,0], "max": [1,1,1]}, "transform": {"scale": 1e12}}],
          "seeds": [{"position": [0,0,0]}]})",
       "vertex 2 at (1000000000000, 0, 0) lies beyond 1e+09 m of the origin"},
  };
  for (const auto& c : cases) {
    const std::string f = test::write_text(dir / "s.json", c.text);
    const std::string e = error_of([&] { load_scene(f); });
    EXPECT_NE(e.find(c.expect), std::string::npos) << "got: " << e << "\nwanted: " << c.expect;
    EXPECT_NE(e.find("s.json"), std::string::npos) << e;
  }
}

// A base that leads back to its own file recursed until the stack ran out (SIGSEGV).
TEST(JsonScene, BasesThatFormACycleAreNamed) {
  const auto dir = test::temp_dir("jsoncycle");
  const std::string self = test::write_text(dir / "self.json", R"({"schema_version": 1, "base": "self.json"})");
  EXPECT_EQ(error_of([&] { load_scene(self); }),
            fmt::format("{0}: at /base: the scene bases form a cycle: {0} -> {0}", self));
  const std::string a = test::write_text(dir / "a.json", R"({"schema_version": 1, "base": "b.json"})");
  const std::string b = test::write_text(dir / "b.json", R"({"schema_version": 1, "base": "a.json"})");
  EXPECT_EQ(error_of([&] { load_scene(a); }),
            fmt::format("{1}: at /base: the scene bases form a cycle: {0} -> {1} -> {0}", a, b));
}

TEST(JsonScene, BasesNestAtMostSixteenFilesDeep) {
  const auto dir = test::temp_dir("jsondeep");
  // base0.json has a real base; each next file is based on the one before.
  test::write_text(dir / "base0.json", R"({"schema_version": 1, "base": "wall"})");
  for (int k = 1; k <= 16; ++k)
    test::write_text(dir / fmt::format("base{}.json", k),
                     fmt::format(R"({{"schema_version": 1, "base": "base{}.json"}})", k - 1));
  EXPECT_EQ(load_scene((dir / "base15.json").string()).meshes.size(), load_scene("wall").meshes.size());
  const std::string e = error_of([&] { load_scene((dir / "base16.json").string()); });
  EXPECT_EQ(e.rfind((dir / "base1.json").string() + ": at /base: scene bases nest more than 16 files deep: ", 0), 0u)
      << e;
}

// tinyobjloader reads what it cannot parse as 0 and indices with atoi, silently.
TEST(MeshScene, ObjNumbersAreCheckedWithTheirLine) {
  const auto dir = test::temp_dir("objcheck");
  struct Case {
    const char* text;
    const char* expect;
  } cases[] = {
      {"v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", ":3: vertex (v x y z): 'nan' is not a finite number"},
      {"v 0 0 0\nv 1 0 0\nv inf 1 0\nf 1 2 3\n", ":3: vertex (v x y z): 'inf' is not a finite number"},
      {"v 0 0 0\nv 1 0 0\nv 1e400 1 0\nf 1 2 3\n", ":3: vertex (v x y z): '1e400' is out of the range of a number"},
      {"v 0 0 0\nv 1 0 0\nv 0 1\nf 1 2 3\n", ":3: vertex (v x y z) has 2 numbers; expected at least 3"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 x\nf 1 2 3\n", ":3: vertex (v x y z): 'x' is not a number"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n",
       ":4: face: vertex index 99999999999999999999 is out of range; 3 vertices are defined before this line "
       "(expected 1 to 3 or -1 to -3)"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", ":4: face: vertex index -4 is out of range"},
      {"v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n", ":3: face: vertex index 3 is out of range; 2 vertices are"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", ":4: face: vertex index 0 is out of range"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/x\n", ":4: face: texture coordinate index 'x' is not an integer"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3//1\n", ":4: face: normal index 1 is out of range; 0 normals are"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", ":4: face has 2 corners; expected at least 3"},
      {"v 0 0 0\r\nv 1 0 0\rv 0 1 nan\n", ":3: vertex (v x y z): 'nan'"},
  };
  for (const auto& c : cases) {
    const std::string f = test::write_text(dir / "m.obj", c.text);
    const std::string e = error_of([&] { (void)load_obj(f); });
    EXPECT_EQ(e.rfind(f + c.expect, 0), 0u) << "got: " << e << "\nwanted: " << f << c.expect;
  }
  // What the checks must not refuse: comments, relative indices, slashes, polygons, w and colours.
  const std::string ok = test::write_text(dir / "ok.obj",
                                          "# a quad\nv 0 0 0 1\nv 1 0 0 # end\nv 1 1 0 0.5 0.5 0.5\nv 0 1 0\n"
                                          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 -2/-2/-1 -1/-1/1\n");
  EXPECT_EQ(load_obj(ok).triangles.size(), 2u);
  for (const auto& name : bundled_meshes()) EXPECT_NO_THROW((void)load_obj(mesh_path(name))) << name;
}

}  // namespace
}  // namespace growbench
