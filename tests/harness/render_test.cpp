// POV-Ray rendering: the scene writer, real renders through Debian's povray, failures recorded rather
// than thrown, the plant snapshot that renders read back, and the comparison grid.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <set>
#include <sstream>

#include <cairo.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <stb_image.h>

#include "harness/output/exporters.hpp"
#include "harness/render/render.hpp"
#include "harness/render/render_results.hpp"
#include "harness/run/process.hpp"
#include "scenes/geometry.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

struct Image {
  int w = 0, h = 0;
  std::vector<unsigned char> rgb;
};

Image load_png(const std::string& path) {
  Image im;
  int n = 0;
  unsigned char* data = stbi_load(path.c_str(), &im.w, &im.h, &n, 3);
  if (!data) {
    ADD_FAILURE() << "cannot read " << path;
    return im;
  }
  im.rgb.assign(data, data + static_cast<std::size_t>(im.w) * im.h * 3);
  stbi_image_free(data);
  return im;
}

double luminance_variance(const Image& im) {
  double s = 0, s2 = 0;
  const std::size_t n = im.rgb.size() / 3;
  for (std::size_t i = 0; i < n; ++i) {
    const double y = 0.299 * im.rgb[3 * i] + 0.587 * im.rgb[3 * i + 1] + 0.114 * im.rgb[3 * i + 2];
    s += y;
    s2 += y * y;
  }
  return s2 / static_cast<double>(n) - (s / static_cast<double>(n)) * (s / static_cast<double>(n));
}

std::filesystem::path fs_concat(std::filesystem::path p, const std::string& tail) {
  return p.concat(tail);
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A wall 2 m wide and 2 m high in the plane z = 0, a camera in front of it, the default sun.
Scene tiny_scene() {
  Scene s = test::scene_with(geom::make_box("wall", {-1.0f, 0.0f, -0.1f}, {1.0f, 2.0f, 0.0f}));
  s.name = "tiny";
  s.camera = {{0.0f, 1.0f, 4.0f}, {0.0f, 1.0f, 0.0f}, 45.0f};
  return s;
}

// A small plant in front of the wall: a stem up the middle with two side branches, four leaves and a
// flower.
Plant tiny_plant() {
  Plant p;
  auto add = [&](glm::vec3 pos, float r, int parent) {
    PlantNode n;
    n.position = pos;
    n.radius = r;
    n.parent = parent;
    p.nodes.push_back(n);
    return static_cast<int>(p.nodes.size()) - 1;
  };
  int prev = add({0.0f, 0.1f, 0.2f}, 0.04f, kNoParent);
  for (int i = 1; i <= 8; ++i) prev = add({0.0f, 0.1f + 0.2f * i, 0.2f}, 0.04f - 0.004f * i, prev);
  const int a = add({0.4f, 1.2f, 0.2f}, 0.015f, 4);
  add({0.7f, 1.5f, 0.2f}, 0.01f, a);
  const int b = add({-0.4f, 1.0f, 0.2f}, 0.015f, 3);
  add({-0.6f, 1.4f, 0.2f}, 0.01f, b);
  for (int i = 0; i < 4; ++i) {
    Organ o;
    o.position = p.nodes[static_cast<std::size_t>(2 + 2 * i)].position;
    o.orientation = glm::angleAxis(glm::radians(90.0f * i), glm::vec3(0, 1, 0)) *
                    glm::angleAxis(glm::radians(-60.0f), glm::vec3(1, 0, 0));
    o.size = 0.25f;
    o.node = 2 + 2 * i;
    p.organs.push_back(o);
  }
  Organ f;
  f.position = p.nodes[8].position;
  f.kind = OrganKind::Flower;
  f.size = 0.15f;
  f.node = 8;
  p.organs.push_back(f);
  PlantPolygon poly;
  poly.vertices = {{0.2f, 0.3f, 0.3f}, {0.4f, 0.3f, 0.3f}, {0.4f, 0.5f, 0.3f}, {0.2f, 0.5f, 0.3f}};
  p.polygons.push_back(poly);
  return p;
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A 64 x 64 decal image written with cairo: its top-left quadrant opaque red (u < 0.5 and v > 0.5, the
// image's top row being v = 1), the rest fully transparent.
void write_decal_png(const std::filesystem::path& path) {
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 64, 64);  // starts transparent
  cairo_t* c = cairo_create(surface);
  cairo_set_source_rgba(c, 1, 0, 0, 1);
  cairo_rectangle(c, 0, 0, 32, 32);
  cairo_fill(c);
  cairo_destroy(c);
  EXPECT_EQ(cairo_surface_write_to_png(surface, path.c_str()), CAIRO_STATUS_SUCCESS) << path;
  cairo_surface_destroy(surface);
}

// Where point p appears in a w x h render from `camera`, as the writer sets POV-Ray's camera up (vertical
// field of view, square pixels, the image not mirrored): (column, row).
glm::ivec2 pixel_of(const Camera& camera, int w, int h, const glm::vec3& p) {
  const glm::vec3 f = glm::normalize(camera.look_at - camera.position);
  const glm::vec3 r = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
  const glm::vec3 u = glm::cross(r, f);
  const glm::vec3 d = p - camera.position;
  const float t = std::tan(0.5f * glm::radians(camera.fov_deg));
  const float x = glm::dot(d, r) / glm::dot(d, f) / (t * static_cast<float>(w) / static_cast<float>(h));
  const float y = glm::dot(d, u) / glm::dot(d, f) / t;
  return {static_cast<int>(0.5f * (x + 1.0f) * static_cast<float>(w)),
          static_cast<int>(0.5f * (1.0f - y) * static_cast<float>(h))};
}

glm::ivec3 rgb_at(const Image& im, const glm::ivec2& px) {
  if (px.x < 0 || px.y < 0 || px.x >= im.w || px.y >= im.h) {
    ADD_FAILURE() << "pixel (" << px.x << ", " << px.y << ") is outside the image";
    return glm::ivec3(-1000);
  }
  const std::size_t i = 3 * (static_cast<std::size_t>(px.y) * static_cast<std::size_t>(im.w) + px.x);
  return {im.rgb[i], im.rgb[i + 1], im.rgb[i + 2]};
}

bool is_red(const glm::ivec3& c) {
  return c.r > 100 && c.g < 40 && c.b < 40;
}

int max_difference(const glm::ivec3& a, const glm::ivec3& b) {
  const glm::ivec3 d = glm::abs(a - b);
  return std::max({d.r, d.g, d.b});
}

std::string show(const glm::ivec3& c) {
  return "(" + std::to_string(c.r) + ", " + std::to_string(c.g) + ", " + std::to_string(c.b) + ")";
}

// A quad 2 m wide and 2 m high in the plane z = 0, facing the camera, its texture coordinates mirrored
// left to right (u = 1 at x = -1): an image lands where only the coordinates put it.
Scene uv_quad_scene() {
  TriangleMesh quad;
  quad.name = "quad";
  quad.vertices = {{-1, 0, 0}, {1, 0, 0}, {1, 2, 0}, {-1, 2, 0}};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  quad.uvs = {{1, 0}, {0, 0}, {0, 1}, {1, 1}};
  quad.uv_triangles = quad.triangles;
  Scene s = test::scene_with(quad);
  s.name = "quad";
  s.camera = {{0.0f, 1.0f, 4.0f}, {0.0f, 1.0f, 0.0f}, 45.0f};
  return s;
}

// A climbable wall whose face is the plane z = -0.5 and, in front of it, a post that is not climbable.
Scene planar_scene() {
  Scene s = test::scene_with(geom::make_box("wall", {-2.0f, 0.0f, -1.5f}, {2.0f, 2.0f, -0.5f}));
  TriangleMesh post = geom::make_box("post", {-0.5f, 1.2f, -0.4f}, {-0.1f, 1.8f, 0.0f});
  post.climbable = false;
  s.meshes.push_back(post);
  s.name = "planar";
  s.camera = {{0.0f, 1.0f, 4.0f}, {0.0f, 1.0f, 0.0f}, 45.0f};
  return s;
}

// A planar decal tilted out of the wall's plane (u_axis leans along z), so its projection onto the wall
// depends on z being carried into POV-Ray's coordinates: on the face z = -0.5, image u = (x + 0.75) / 2.5
// and v = y / 2.
SurfaceDecal tilted_planar_decal(const std::string& image) {
  SurfaceDecal d;
  d.image = image;
  d.mesh = kPlanarDecal;
  d.origin = {-1.0f, 0.0f, 0.0f};
  d.u_axis = {2.0f, 0.0f, 1.0f};
  d.v_axis = {0.0f, 2.0f, 0.0f};
  return d;
}

SurfaceDecal uv_decal(const std::string& image, std::int32_t mesh) {
  SurfaceDecal d;
  d.image = image;
  d.mesh = mesh;
  return d;
}

// A large ground (not climbable) with a small climbable post behind the plant, and a camera 12 m away
// that shows tiny_plant small: its box spans about a fifth of the frame.
Scene far_scene() {
  TriangleMesh ground = geom::make_box("ground", {-10.0f, -0.1f, -10.0f}, {10.0f, 0.0f, 10.0f});
  ground.climbable = false;
  Scene s = test::scene_with(ground);
  s.meshes.push_back(geom::make_box("post", {-0.1f, 0.0f, -0.6f}, {0.1f, 1.0f, -0.4f}));
  s.name = "far";
  s.camera = {{0.0f, 4.0f, 12.0f}, {0.0f, 1.0f, 0.0f}, 45.0f};
  return s;
}

// The projected box of `points` in `camera`'s frame: (min x, min y) and (max x, max y), in [-1, 1] across.
std::pair<glm::vec2, glm::vec2> projected_box(const Camera& camera, float aspect,
                                              const std::vector<glm::vec3>& points) {
  glm::vec2 lo(1e9f), hi(-1e9f);
  for (const glm::vec3& p : points) {
    const glm::vec3 q = project(camera, aspect, p);
    EXPECT_GT(q.z, 0.0f) << "a point behind the camera";
    lo = glm::min(lo, glm::vec2(q));
    hi = glm::max(hi, glm::vec2(q));
  }
  return {lo, hi};
}

// Every point inside the frame less kFrameMargin on each side, and the points' extent reaching that margin
// on one axis at least (to within `slack`).
void expect_framed(const Camera& camera, float aspect, const std::vector<glm::vec3>& points, float slack = 2e-3f) {
  const auto [lo, hi] = projected_box(camera, aspect, points);
  const float edge = 1.0f - 2.0f * kFrameMargin;  // the margin is a fraction of the frame, which is 2 across
  EXPECT_GE(lo.x, -edge - slack);
  EXPECT_GE(lo.y, -edge - slack);
  EXPECT_LE(hi.x, edge + slack);
  EXPECT_LE(hi.y, edge + slack);
  EXPECT_GE(std::max(hi.x - lo.x, hi.y - lo.y), 2.0f * edge - slack) << "the plant does not fill the frame";
}

TEST(RenderCamera, AutoFramesASmallPlantWithTheMarginKeepingTheViewDirection) {
  const Scene scene = far_scene();
  const Plant plant = tiny_plant();
  const float aspect = 4.0f / 3.0f;
  const Aabb box = plant_bounds(scene, plant);
  // The organs reach their size around them (a leaf on the top node), the nodes their radius.
  EXPECT_NEAR(box.max.y, 1.7f + 0.25f, 1e-5f);
  EXPECT_NEAR(box.min.x, -0.6f - 0.01f, 1e-5f);  // a side branch tip, without organs
  const float before = projected_extent(scene.camera, aspect, box);
  EXPECT_LT(before, kSmallPlantExtent);
  // No scene bounds: no context around the plant, which then fills the frame to the margin.
  const RenderCamera rc = choose_camera(scene.camera, aspect, corners(box), Aabb{}, CameraMode::Auto);
  ASSERT_TRUE(rc.fitted);
  EXPECT_FLOAT_EQ(rc.scene_extent, before);
  EXPECT_FLOAT_EQ(rc.camera.fov_deg, scene.camera.fov_deg);
  EXPECT_GT(glm::dot(camera_frame(rc.camera).forward, camera_frame(scene.camera).forward), 1.0f - 1e-6f);
  expect_framed(rc.camera, aspect, corners(box));
  EXPECT_GT(projected_extent(rc.camera, aspect, box), 0.79f);
  // Off to one side and at another aspect, it is framed and centred all the same.
  Aabb side = box;
  side.min += glm::vec3(3.0f, 0.0f, -2.0f);
  side.max += glm::vec3(3.0f, 0.0f, -2.0f);
  const Camera wide = choose_camera(scene.camera, 2.0f, corners(side), Aabb{}, CameraMode::Auto).camera;
  expect_framed(wide, 2.0f, corners(side));
  const auto [lo, hi] = projected_box(wide, 2.0f, corners(side));
  EXPECT_NEAR(lo.x + hi.x, 0.0f, 1e-3f);
  EXPECT_NEAR(lo.y + hi.y, 0.0f, 1e-3f);
  // camera=scene keeps the scene's camera however small the plant.
  const RenderCamera kept = choose_camera(scene.camera, aspect, corners(box), scene.bounds(), CameraMode::Scene);
  EXPECT_FALSE(kept.fitted);
  EXPECT_EQ(kept.camera.position, scene.camera.position);
}

TEST(RenderCamera, SceneCameraIsKeptWhenThePlantFillsItsFrameOrIsEmpty) {
  Scene scene = tiny_scene();
  scene.camera.position = {0.0f, 1.0f, 2.5f};
  const Aabb box = plant_bounds(scene, tiny_plant());
  EXPECT_GT(projected_extent(scene.camera, 4.0f / 3.0f, box), kSmallPlantExtent);
  const RenderCamera rc =
      choose_camera(scene.camera, 4.0f / 3.0f, plant_points(scene, tiny_plant()), scene.bounds(), CameraMode::Auto);
  EXPECT_FALSE(rc.fitted) << rc.scene_extent << " " << rc.seen.in_frame << " " << rc.seen.visible;
  EXPECT_EQ(rc.camera.position, scene.camera.position);
  EXPECT_EQ(rc.camera.look_at, scene.camera.look_at);
  const auto dir = test::temp_dir("camera_kept");
  write_pov((dir / "a.pov").string(), scene, tiny_plant(), RenderOptions{});
  EXPECT_NE(read_file(dir / "a.pov").find("location <0,1,-2.5> look_at"), std::string::npos);
  // An empty plant has nothing to frame.
  const Scene far = far_scene();
  EXPECT_TRUE(plant_bounds(far, Plant{}).empty());
  const RenderCamera empty =
      choose_camera(far.camera, 4.0f / 3.0f, plant_points(far, Plant{}), far.bounds(), CameraMode::Auto);
  EXPECT_FALSE(empty.fitted);
  EXPECT_EQ(empty.camera.position, far.camera.position);
  write_pov((dir / "e.pov").string(), far, Plant{}, RenderOptions{});
  EXPECT_NE(read_file(dir / "e.pov").find("location <0,4,-12>"), std::string::npos);
}

TEST(RenderCamera, AHiddenPlantIsSeenFromAroundWhatHidesIt) {
  // The plant behind the wall of tiny_scene (z < -0.1), the camera in front: every sight line from the
  // front crosses the wall's plane within it, and none from behind does.
  const Scene scene = tiny_scene();
  Plant plant = tiny_plant();
  for (PlantNode& n : plant.nodes) n.position.z -= 1.0f;
  for (Organ& o : plant.organs) o.position.z -= 1.0f;
  for (PlantPolygon& poly : plant.polygons)
    for (glm::vec3& v : poly.vertices) v.z -= 1.0f;
  const std::vector<glm::vec3> points = plant_points(scene, plant);
  const SightBlocked wall = [](const glm::vec3& eye, const glm::vec3& p) {
    if ((eye.z > 0.0f) == (p.z > 0.0f) || eye.z == p.z) return false;
    const float t = eye.z / (eye.z - p.z);
    const glm::vec3 q = eye + t * (p - eye);
    return std::abs(q.x) <= 1.0f && q.y >= 0.0f && q.y <= 2.0f;
  };
  const float aspect = 4.0f / 3.0f;
  EXPECT_FLOAT_EQ(sight(scene.camera, aspect, points, wall).visible, 0.0f);
  EXPECT_FLOAT_EQ(sight(scene.camera, aspect, points, {}).visible, 1.0f);  // nothing blocks
  const RenderCamera rc = choose_camera(scene.camera, aspect, points, scene.bounds(), CameraMode::Auto, wall);
  ASSERT_TRUE(rc.fitted);
  EXPECT_GE(rc.seen.visible, kVisibleEnough);
  EXPECT_FLOAT_EQ(rc.seen.in_frame, 1.0f);  // never cropped
  EXPECT_TRUE(rc.turn_deg != 0.0f || rc.raise_deg != 0.0f) << "the camera went round or over the wall";
  // camera=scene keeps the scene's view and says how little it sees.
  const RenderCamera kept = choose_camera(scene.camera, aspect, points, scene.bounds(), CameraMode::Scene, wall);
  EXPECT_FALSE(kept.fitted);
  EXPECT_FLOAT_EQ(kept.seen.visible, 0.0f);
}

TEST(RenderCamera, APlantLargerThanTheSceneFrameIsFittedNotCropped) {
  Scene scene = tiny_scene();
  Plant plant = tiny_plant();
  plant.nodes[1].position.y = 9.0f;  // far above the frame's top edge
  const std::vector<glm::vec3> points = plant_points(scene, plant);
  const RenderCamera rc = choose_camera(scene.camera, 4.0f / 3.0f, points, scene.bounds(), CameraMode::Auto);
  EXPECT_LT(sight(scene.camera, 4.0f / 3.0f, points, {}).in_frame, 1.0f);
  ASSERT_TRUE(rc.fitted);
  EXPECT_FLOAT_EQ(rc.seen.in_frame, 1.0f);
  for (const glm::vec3& p : points) {
    const glm::vec3 q = project(rc.camera, 4.0f / 3.0f, p);
    EXPECT_LE(std::max(std::abs(q.x), std::abs(q.y)), 1.0f - 2.0f * kFrameMargin + 2e-3f);
  }
}

TEST(RenderCamera, PlantPointsSampleNodesEvenlyAndKeepOrgans) {
  const Scene scene = tiny_scene();
  Plant plant;
  for (int i = 0; i < 1000; ++i) {
    PlantNode n;
    n.position = {0.0f, 0.001f * static_cast<float>(i), 0.0f};
    plant.nodes.push_back(n);
  }
  Organ leaf;
  leaf.position = {5.0f, 0.0f, 0.0f};
  plant.organs.push_back(leaf);
  const std::vector<glm::vec3> pts = plant_points(scene, plant, 100);
  // Every tenth node, the last tip, and the organ.
  ASSERT_EQ(pts.size(), 102u);
  EXPECT_FLOAT_EQ(pts[1].y, 0.001f * 10.0f);
  EXPECT_FLOAT_EQ(pts[100].y, 0.001f * 999.0f);
  EXPECT_EQ(pts[101], leaf.position);
  EXPECT_TRUE(plant_points(scene, Plant{}).empty());
}

TEST(RenderCamera, APlantWithDecalsIsFramedByThem) {
  // The decals stand for the plant: its nodes (far off here) do not count, the decal's rectangle and the
  // mesh a decal follows do.
  Scene scene = uv_quad_scene();
  Plant p;
  PlantNode far_node;
  far_node.position = {50.0f, 0.0f, 0.0f};
  p.nodes.push_back(far_node);
  p.decals = {tilted_planar_decal("a.png")};
  Aabb box = plant_bounds(scene, p);
  EXPECT_EQ(box.min, glm::vec3(-1.0f, 0.0f, 0.0f));
  EXPECT_EQ(box.max, glm::vec3(1.0f, 2.0f, 1.0f));
  p.decals = {uv_decal("a.png", 0)};
  box = plant_bounds(scene, p);
  EXPECT_EQ(box.min, glm::vec3(-1.0f, 0.0f, 0.0f));
  EXPECT_EQ(box.max, glm::vec3(1.0f, 2.0f, 0.0f));
}

TEST(RenderCamera, TurntableFramesOrbitTheAxisAtOneDistanceWithThePlantInFrame) {
  const Scene scene = far_scene();
  Plant plant = tiny_plant();
  plant.nodes[10].position.x += 1.0f;  // lopsided, so a fit to each angle's view would vary
  const Aabb box = plant_bounds(scene, plant);
  const float aspect = 4.0f / 3.0f;
  const int n = 7;
  std::vector<glm::vec3> positions;
  for (int k = 0; k < n; ++k) {
    const Orbit o = turntable_camera(scene.camera, aspect, box, k, n);
    EXPECT_NEAR(o.angle, 2.0f * std::numbers::pi_v<float> * static_cast<float>(k) / n, 1e-5f);
    EXPECT_EQ(o.axis_point, box.center());
    positions.push_back(o.camera.position);
    // In frame, with the margin, at every angle (a prism around the swept cylinder is fitted, so the
    // plant's own box lies inside it).
    const auto [lo, hi] = projected_box(o.camera, aspect, corners(box));
    for (const float v : {lo.x, lo.y, hi.x, hi.y}) EXPECT_LE(std::abs(v), 0.8f + 2e-3f) << "frame " << k;
    EXPECT_GT(projected_extent(o.camera, aspect, box), 0.5f) << "frame " << k;
    EXPECT_FLOAT_EQ(o.camera.fov_deg, scene.camera.fov_deg);
  }
  // Frame 0 looks the scene camera's way; all are at one distance from the axis and one height, and
  // distinct.
  const Orbit first = turntable_camera(scene.camera, aspect, box, 0, n);
  EXPECT_GT(glm::dot(camera_frame(first.camera).forward, camera_frame(scene.camera).forward), 1.0f - 1e-6f);
  const glm::vec2 axis(box.center().x, box.center().z);
  const float r0 = glm::length(glm::vec2(positions[0].x, positions[0].z) - axis);
  EXPECT_GT(r0, 1.0f);
  for (int k = 0; k < n; ++k) {
    EXPECT_NEAR(glm::length(glm::vec2(positions[k].x, positions[k].z) - axis), r0, 1e-4f * r0) << "frame " << k;
    EXPECT_NEAR(positions[k].y, positions[0].y, 1e-4f * r0);
    for (int m = 0; m < k; ++m) EXPECT_GT(glm::length(positions[k] - positions[m]), 0.5f * r0) << k << " and " << m;
  }
  // The .pov files follow: each frame its own camera, and the light turned with it.
  const auto dir = test::temp_dir("turntable_pov");
  RenderOptions o;
  o.turns = n;
  std::set<std::string> cameras, lights;
  for (int k = 0; k < n; ++k) {
    o.turn = k;
    write_pov((dir / "t.pov").string(), scene, plant, o);
    const std::string pov = read_file(dir / "t.pov");
    cameras.insert(pov.substr(pov.find("camera {"), pov.find('\n', pov.find("camera {")) - pov.find("camera {")));
    lights.insert(pov.substr(pov.find("light_source {"), 60));
  }
  EXPECT_EQ(cameras.size(), static_cast<std::size_t>(n));
  EXPECT_EQ(lights.size(), static_cast<std::size_t>(n));
  o.turn = n;
  EXPECT_NE(test::error_of([&] { write_pov((dir / "t.pov").string(), scene, plant, o); }).find("turntable frame"),
            std::string::npos);
}

TEST(PovWriter, DepthOfFieldFocusesOnThePlantAndKeepsItSharp) {
  const auto dir = test::temp_dir("pov_dof");
  const Scene scene = far_scene();
  const Plant plant = tiny_plant();
  RenderOptions o;
  o.quality = RenderQuality::Paper;
  write_pov((dir / "sharp.pov").string(), scene, plant, o);
  EXPECT_EQ(read_file(dir / "sharp.pov").find("aperture"), std::string::npos);
  o.dof = true;
  write_pov((dir / "dof.pov").string(), scene, plant, o);
  const std::string pov = read_file(dir / "dof.pov");
  const RenderView view = render_view(scene, plant, o);
  const glm::vec3 c = view.subject.center();
  EXPECT_NE(pov.find(fmt::format("focal_point <{:.6g},{:.6g},{:.6g}>", c.x, c.y, -c.z)), std::string::npos) << pov;
  EXPECT_NE(pov.find("blur_samples"), std::string::npos);
  // The aperture keeps the box's corners within kSharpBlur of the frame's height (POV-Ray's lens is half
  // the aperture across), and one of them, or the far background, at the limit.
  const FocalBlur fb = focal_blur(view.camera, view.subject);
  EXPECT_NE(pov.find(fmt::format("aperture {:.6g} ", fb.aperture)), std::string::npos);
  ASSERT_GT(fb.aperture, 0.0f);
  const CameraFrame f = camera_frame(view.camera);
  const float focus = glm::dot(c - view.camera.position, f.forward);
  const float frame_h = 2.0f * focus * std::tan(0.5f * glm::radians(view.camera.fov_deg));
  float worst = 0.0f;
  for (const glm::vec3& p : corners(view.subject)) {
    const float d = glm::dot(p - view.camera.position, f.forward);
    worst = std::max(worst, 0.5f * fb.aperture * std::abs(d - focus) / d / frame_h);
  }
  EXPECT_LE(worst, kSharpBlur * 1.001f);
  EXPECT_TRUE(worst > kSharpBlur * 0.999f || 0.5f * fb.aperture / frame_h > kMaxBlur * 0.999f);
  // The preview refuses it, naming the option.
  o.quality = RenderQuality::Preview;
  EXPECT_NE(test::error_of([&] { write_pov((dir / "p.pov").string(), scene, plant, o); }).find("--dof"),
            std::string::npos);
}

TEST(PovWriter, StudioBackdropReplacesSkyAndGroundAndKeepsWhatThePlantClimbs) {
  const auto dir = test::temp_dir("pov_studio");
  const Scene scene = far_scene();
  RenderOptions o;
  write_pov((dir / "scene.pov").string(), scene, tiny_plant(), o);
  const std::string with_scene = read_file(dir / "scene.pov");
  EXPECT_NE(with_scene.find("sky_sphere"), std::string::npos);
  EXPECT_NE(with_scene.find("plane {"), std::string::npos);
  EXPECT_NE(with_scene.find("scene mesh 'ground'"), std::string::npos);
  o.backdrop = Backdrop::Studio;
  write_pov((dir / "studio.pov").string(), scene, tiny_plant(), o);
  const std::string studio = read_file(dir / "studio.pov");
  EXPECT_EQ(studio.find("sky_sphere"), std::string::npos);
  EXPECT_EQ(studio.find("plane {"), std::string::npos);
  EXPECT_EQ(studio.find("scene mesh 'ground'"), std::string::npos);  // not climbable
  EXPECT_NE(studio.find("scene mesh 'post'"), std::string::npos);
  EXPECT_NE(studio.find("texture { GB_Studio }"), std::string::npos);
  EXPECT_NE(studio.find("background {"), std::string::npos);
  EXPECT_EQ(count_of(studio, "\n  cone {"), tiny_plant().nodes.size() - 1);  // the plant is all there
}

// A decal whose mesh's layout went beyond the unit square spans its rectangle of the mesh's coordinates:
// the image is scaled and moved in UV space.
TEST(PovWriter, AUvDecalSpansItsRectangleOfTheMeshsCoordinates) {
  const auto dir = test::temp_dir("pov_uvrect");
  TriangleMesh quad = geom::make_box("quad", {-1.0f, 0.0f, -0.1f}, {1.0f, 2.0f, 0.0f});
  quad.uvs.assign(quad.vertices.size(), glm::vec2(2.0f, -1.0f));
  for (const auto& t : quad.triangles) quad.uv_triangles.push_back(t);
  const Scene scene = test::scene_with(quad);
  Plant plant = tiny_plant();
  plant.decals = {{"texture.png", 0, {1.0f, -2.0f, 0.0f}, {3.0f, 0.0f, 0.0f}, {0.0f, 3.0f, 0.0f}}};
  RenderOptions o;
  write_pov((dir / "s.pov").string(), scene, plant, o);
  EXPECT_NE(read_file(dir / "s.pov")
                .find("image_map { png \"texture.png\" once interpolate 2 } scale <3,3,1> "
                      "translate <1,-2,0> }"),
            std::string::npos);
  plant.decals[0] = {"texture.png", 0, {}, {}, {}};  // the unit square: as before
  write_pov((dir / "u.pov").string(), scene, plant, o);
  EXPECT_NE(read_file(dir / "u.pov").find("image_map { png \"texture.png\" once interpolate 2 } }"), std::string::npos);
}

// A collision-only mesh (visible: false) is in neither the render nor the exported scene, with any backdrop.
TEST(PovWriter, ACollisionOnlyMeshIsNotDrawn) {
  const auto dir = test::temp_dir("pov_hidden");
  Scene scene = far_scene();
  scene.meshes.push_back(geom::make_box("guide", {-0.2f, 0.0f, -0.7f}, {0.2f, 1.1f, -0.3f}));
  scene.meshes.back().visible = false;
  RenderOptions o;
  for (const Backdrop b : {Backdrop::Scene, Backdrop::Studio}) {
    o.backdrop = b;
    write_pov((dir / "s.pov").string(), scene, tiny_plant(), o);
    const std::string pov = read_file(dir / "s.pov");
    EXPECT_NE(pov.find("scene mesh 'post'"), std::string::npos);
    EXPECT_EQ(pov.find("scene mesh 'guide'"), std::string::npos);
  }
  write_scene_glb((dir / "scene.glb").string(), scene);
  const std::string glb = read_file(dir / "scene.glb");
  EXPECT_NE(glb.find("\"post\""), std::string::npos);
  EXPECT_EQ(glb.find("\"guide\""), std::string::npos);
}

TEST(PovRender, AutoCameraFillsTheFrameWithASmallPlant) {
  ASSERT_FALSE(find_povray().empty()) << "povray is not installed (scripts/install-deps installs it)";
  const auto dir = test::temp_dir("render_auto");
  const Scene scene = far_scene();
  RenderOptions o;
  o.width = 160;
  o.height = 120;
  // The plant's pixels: where the render differs from the one without it (same camera: it frames the
  // plant whether or not it is drawn). Returns the fraction of the frame's width and height they span.
  auto plant_span = [&](CameraMode mode, const std::string& name) {
    o.camera = mode;
    o.draw_plant = true;
    const RenderResult with =
        render_plant(scene, tiny_plant(), (dir / (name + ".pov")).string(), (dir / (name + ".png")).string(), o);
    EXPECT_TRUE(with.ok()) << with.message;
    EXPECT_TRUE(with.warnings.empty()) << with.warnings.front();
    o.draw_plant = false;
    const RenderResult bare = render_plant(scene, tiny_plant(), (dir / (name + "_bare.pov")).string(),
                                           (dir / (name + "_bare.png")).string(), o);
    EXPECT_TRUE(bare.ok()) << bare.message;
    const Image a = load_png(with.png), b = load_png(bare.png);
    glm::ivec2 lo(a.w, a.h), hi(-1);
    for (int y = 0; y < a.h; ++y)
      for (int x = 0; x < a.w; ++x) {
        const std::size_t i = 3 * (static_cast<std::size_t>(y) * a.w + x);
        int d = 0;
        for (int c = 0; c < 3; ++c) d += std::abs(a.rgb[i + c] - b.rgb[i + c]);
        if (d > 30) {
          lo = glm::min(lo, glm::ivec2(x, y));
          hi = glm::max(hi, glm::ivec2(x, y));
        }
      }
    return std::make_pair(with.camera, glm::vec2(hi - lo + 1) / glm::vec2(a.w, a.h));
  };
  const auto [fitted, big] = plant_span(CameraMode::Auto, "auto");
  const auto [kept, small] = plant_span(CameraMode::Scene, "scene");
  EXPECT_EQ(fitted, "fitted");
  EXPECT_EQ(kept, "scene");
  EXPECT_LT(std::max(small.x, small.y), 0.3f) << small.x << " x " << small.y;
  // The plant (its shadow too) spans most of the frame on one axis, inside the margin's 80% or about.
  EXPECT_GT(std::max(big.x, big.y), 0.6f) << big.x << " x " << big.y;
}

TEST(PlantSnapshot, RoundTripsBitForBit) {
  const auto dir = test::temp_dir("snapshot");
  const Plant p = tiny_plant();
  const auto bytes = write_plant_snapshot((dir / "p.gbplant").string(), p);
  EXPECT_EQ(bytes, std::filesystem::file_size(dir / "p.gbplant"));
  const Plant q = read_plant_snapshot((dir / "p.gbplant").string());
  EXPECT_EQ(q.geometry_hash(), p.geometry_hash());
  ASSERT_EQ(q.organs.size(), p.organs.size());
  EXPECT_EQ(q.organs.back().kind, OrganKind::Flower);
  EXPECT_EQ(q.polygons.size(), 1u);
}

TEST(PlantSnapshot, BadFilesAreClearErrors) {
  const auto dir = test::temp_dir("snapshot_bad");
  const std::string path = (dir / "p.gbplant").string();
  write_plant_snapshot(path, tiny_plant());
  std::string data = read_file(path);
  test::write_text(dir / "cut.gbplant", data.substr(0, data.size() / 2));
  EXPECT_NE(
      test::error_of([&] { read_plant_snapshot((dir / "cut.gbplant").string()); }).find("cut.gbplant: plant snapshot"),
      std::string::npos);
  test::write_text(dir / "obj.gbplant", "v 0 0 0\n");
  EXPECT_NE(test::error_of([&] {
              read_plant_snapshot((dir / "obj.gbplant").string());
            }).find("not a growbench plant snapshot"),
            std::string::npos);
  // A parent index past the node itself: the forest's invariant, checked on reading.
  std::string bad = data;
  const std::int32_t wrong = 5;
  std::memcpy(bad.data() + 8 + 8 + 16, &wrong, 4);  // node 0's parent
  test::write_text(dir / "bad.gbplant", bad);
  EXPECT_NE(test::error_of([&] { read_plant_snapshot((dir / "bad.gbplant").string()); }).find("invalid plant"),
            std::string::npos);
}

TEST(PovWriter, SceneMeshesAreSmoothExceptAcrossCreases) {
  const auto dir = test::temp_dir("pov_creases");
  // A box: each corner's three faces meet at 90 degrees, so each corner is split three ways, one normal
  // per face.
  write_pov((dir / "box.pov").string(), tiny_scene(), Plant{}, RenderOptions{});
  const std::string box = read_file(dir / "box.pov");
  EXPECT_NE(box.find("vertex_vectors { 24"), std::string::npos);
  EXPECT_NE(box.find("normal_vectors { 24"), std::string::npos);
  // A 32-sided column: its sides turn by 11.25 degrees, so a side vertex keeps one normal, and only the
  // caps' rims are split from the sides.
  const TriangleMesh col = geom::make_cylinder("column", {0, 0, 0}, {0, 2, 0}, 0.3f, 0.3f, 32);
  write_pov((dir / "col.pov").string(), test::scene_with(col), Plant{}, RenderOptions{});
  const std::string pov = read_file(dir / "col.pov");
  const std::smatch m = [&] {
    std::smatch r;
    std::regex_search(pov, r, std::regex(R"(normal_vectors \{ (\d+),)"));
    return r;
  }();
  ASSERT_FALSE(m.empty());
  // Each rim vertex once for the side and once for its cap (and a cap's centre, if it has one).
  EXPECT_LE(std::stoul(m[1]), 2 * col.vertices.size());
  EXPECT_GE(std::stoul(m[1]), col.vertices.size() + 2 * 32 - 2);
  // Neighbouring side normals differ by the turn, not by the face: the first 4 normals are unit and
  // horizontal or vertical.
  EXPECT_EQ(pov.find("normal_vectors { 0"), std::string::npos);
}

TEST(PovRender, ThePlantsPixelShareIsMeasuredByAMask) {
  ASSERT_FALSE(find_povray().empty()) << "povray is not installed (scripts/install-deps installs it)";
  const auto dir = test::temp_dir("render_mask");
  Scene scene = tiny_scene();
  RenderOptions o;
  o.width = 160;
  o.height = 120;
  o.camera = CameraMode::Scene;
  const RenderResult r = render_plant(scene, tiny_plant(), (dir / "a.pov").string(), (dir / "a.png").string(), o);
  ASSERT_TRUE(r.ok()) << r.message;
  // The plant's pixels, counted as PovRender.AutoCameraFillsTheFrameWithASmallPlant does: where the render
  // differs from the scene alone (its shadow counts there, so that count is the larger).
  o.draw_plant = false;
  const RenderResult bare = render_plant(scene, tiny_plant(), (dir / "b.pov").string(), (dir / "b.png").string(), o);
  ASSERT_TRUE(bare.ok()) << bare.message;
  EXPECT_LT(bare.plant_pixel_share, 0.0) << "no plant drawn: not measured";
  const Image a = load_png(r.png), b = load_png(bare.png);
  std::size_t differ = 0;
  for (std::size_t i = 0; i + 2 < a.rgb.size(); i += 3)
    if (std::abs(a.rgb[i] - b.rgb[i]) + std::abs(a.rgb[i + 1] - b.rgb[i + 1]) + std::abs(a.rgb[i + 2] - b.rgb[i + 2]) >
        30)
      ++differ;
  const double by_difference = static_cast<double>(differ) / (a.w * a.h);
  EXPECT_GT(r.plant_pixel_share, 0.2 * by_difference);
  EXPECT_LT(r.plant_pixel_share, 1.5 * by_difference);
  EXPECT_GT(r.plant_pixel_share, 0.0);
  // The mask's image and log are not left beside the render.
  EXPECT_FALSE(std::filesystem::exists(dir / "a.mask.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "a.mask.png.log"));
  EXPECT_NEAR(r.to_json().at("plant_pixel_share").get<double>(), r.plant_pixel_share, 1e-12);
}

// A thin plant lying flat on the ground, seen edge-on from the scene camera's height: a zig-zag of
// segments a few millimetres thick across the floor in front of the wall.
Plant flat_plant() {
  Plant p;
  int prev = kNoParent;
  for (int i = 0; i <= 12; ++i) {
    PlantNode n;
    n.position = {i % 2 == 0 ? -0.8f : 0.8f, 0.005f, 0.2f + 0.1f * static_cast<float>(i)};
    n.radius = 0.004f;
    n.parent = prev;
    p.nodes.push_back(n);
    prev = static_cast<int>(p.nodes.size()) - 1;
  }
  return p;
}

TEST(PovRender, APlantOnFewPixelsIsLookedAtFromTheRingCameraShowingMostOfIt) {
  ASSERT_FALSE(find_povray().empty()) << "povray is not installed (scripts/install-deps installs it)";
  const auto dir = test::temp_dir("render_few_pixels");
  Scene scene = tiny_scene();
  scene.camera = {{0.0f, 0.005f, 4.0f}, {0.0f, 0.005f, 0.0f}, 45.0f};  // level with the plant: edge-on
  RenderOptions o;
  o.width = 160;
  o.height = 120;
  o.min_branch_px = 0.0f;
  const Plant plant = flat_plant();
  // The rule's first choice: the first ring camera, level with the plant, which sees all its points but
  // next to none of its pixels.
  const std::vector<RenderView> ring = ring_views(scene, plant, o, render_view(scene, plant, o));
  ASSERT_FALSE(ring.empty());
  EXPECT_EQ(ring.front().raise_deg, 0.0f);
  EXPECT_EQ(render_view(scene, plant, o).raise_deg, 0.0f);
  const RenderResult r = render_plant(scene, plant, (dir / "a.pov").string(), (dir / "a.png").string(), o);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_GE(r.plant_pixel_share, kFewPlantPixels);
  const std::string pov = read_file(dir / "a.pov");
  EXPECT_NE(pov.find("raised 50 deg"), std::string::npos) << "the view from highest above shows the flat plant best";
  // The probes leave nothing behind.
  for (const char* f : {"a.probe.pov", "a.probe.mask.png", "a.probe.mask.png.log", "a.mask.png"})
    EXPECT_FALSE(std::filesystem::exists(dir / f)) << f;
  // The scene camera is never second-guessed.
  o.camera = CameraMode::Scene;
  const RenderResult kept = render_plant(scene, plant, (dir / "b.pov").string(), (dir / "b.png").string(), o);
  ASSERT_TRUE(kept.ok()) << kept.message;
  EXPECT_LT(kept.plant_pixel_share, kFewPlantPixels);
  EXPECT_EQ(kept.camera, "scene");
}

TEST(PovWriter, ThinBranchesAreDrawnAtLeastTheLeastPixelWidth) {
  const auto dir = test::temp_dir("pov_min_px");
  Plant p;
  for (int i = 0; i < 2; ++i) {
    PlantNode n;
    n.position = {0.0f, 1.0f + 0.5f * static_cast<float>(i), 0.2f};  // 3.8 m in front of the camera
    n.radius = 1e-4f;
    n.parent = i == 0 ? kNoParent : 0;
    p.nodes.push_back(n);
  }
  RenderOptions o;
  o.camera = CameraMode::Scene;
  o.width = 480;
  o.height = 360;
  o.min_branch_px = 2.0f;
  write_pov((dir / "a.pov").string(), tiny_scene(), p, o);
  // Two pixels across at depth 3.8 under a 45 degree vertical field over 360 rows: a radius of
  // 3.8 tan(22.5 deg) / 180 = 0.0087445.
  const std::string wide = read_file(dir / "a.pov");
  EXPECT_NE(wide.find(",0.0087445,<0,1.5,-0.2>,0.0087445"), std::string::npos) << wide.substr(wide.find("cone {"), 80);
  o.min_branch_px = 0.0f;
  write_pov((dir / "b.pov").string(), tiny_scene(), p, o);
  const std::string thin = read_file(dir / "b.pov");
  EXPECT_NE(thin.find(",0.0001,<0,1.5,-0.2>,0.0001"), std::string::npos) << thin.substr(thin.find("cone {"), 80);
}

TEST(PovWriter, WritesEveryPartInPovRayHandedness) {
  const auto dir = test::temp_dir("pov");
  const Plant p = tiny_plant();
  RenderOptions o;
  o.camera = CameraMode::Scene;  // the scene camera, whose place in the file is known
  const auto bytes = write_pov((dir / "s.pov").string(), tiny_scene(), p, o);
  const std::string pov = read_file(dir / "s.pov");
  EXPECT_EQ(bytes, pov.size());
  EXPECT_NE(pov.find("#version 3.7;"), std::string::npos);
  EXPECT_NE(pov.find("assumed_gamma 1.0"), std::string::npos);
  EXPECT_EQ(count_of(pov, "\n  cone {"), p.nodes.size() - 1);  // one per segment
  EXPECT_EQ(count_of(pov, "\n  sphere {"), p.nodes.size());    // every joint and tip, and the root (it has children)
  EXPECT_EQ(count_of(pov, " =  // "), 2u);  // one declared mesh per shape, the leaf's and the blossom's ...
  EXPECT_EQ(count_of(pov, "#declare GB_Organ0 =  // leaf"), 1u);
  EXPECT_EQ(count_of(pov, "#declare GB_Organ1 =  // blossom"), 1u);
  EXPECT_EQ(count_of(pov, "object { GB_Organ0 matrix"), 4u);  // ... instanced per organ: the leaves plain,
  // the blossom in its own petal colour (linear: the sRGB 0.97, 0.78, 0.84 of organ_shapes.cpp).
  EXPECT_EQ(count_of(pov, "object { GB_Organ1 texture { pigment { rgb <0.9331,0.5705,0.6739> }"), 1u);
  EXPECT_NE(pov.find("texture { GB_Flower }"), std::string::npos);
  // Right-handed to left-handed: z negated. The root at (0, 0.1, 0.2) and the camera at z = 4.
  EXPECT_NE(pov.find("sphere { <0,0.1,-0.2>,0.04 }"), std::string::npos);
  EXPECT_NE(pov.find("location <0,1,-4>"), std::string::npos);
  // The mesh form of the branches: one mesh2 more, no cones.
  o.branches = "mesh";
  write_pov((dir / "m.pov").string(), tiny_scene(), p, o);
  const std::string mesh = read_file(dir / "m.pov");
  EXPECT_EQ(count_of(mesh, "cone {"), 0u);
  EXPECT_EQ(count_of(mesh, "mesh2 {"), count_of(pov, "mesh2 {") + 1);
  o.branches = "tubes";
  EXPECT_NE(
      test::error_of([&] { write_pov((dir / "x.pov").string(), tiny_scene(), p, o); }).find("expected cones or mesh"),
      std::string::npos);
}

TEST(PovWriter, APlantWithDecalsIsDrawnByThem) {
  const auto dir = test::temp_dir("pov_decals");
  Scene scene = uv_quad_scene();
  TriangleMesh ground = geom::make_box("ground", {-3.0f, -0.1f, -3.0f}, {3.0f, 0.0f, 3.0f});
  ground.climbable = false;
  scene.meshes.push_back(ground);
  Plant p = tiny_plant();
  p.decals = {uv_decal("a.png", 0), tilted_planar_decal("b.png")};
  p.decals[1].origin.z = 0.5f;
  RenderOptions o;
  write_pov((dir / "d.pov").string(), scene, p, o);
  const std::string pov = read_file(dir / "d.pov");
  // The plant's branches, organs and polygons are left out: the decals stand for it.
  EXPECT_EQ(count_of(pov, "cone {"), 0u);
  EXPECT_EQ(count_of(pov, "\n  sphere {"), 0u);
  EXPECT_EQ(count_of(pov, "GB_OrganShape"), 0u);
  EXPECT_EQ(count_of(pov, "// polygons"), 0u);
  // The quad carries its texture coordinates, in its own corner order.
  EXPECT_EQ(count_of(pov, "uv_vectors { 4,\n    <1,0>, <0,0>, <0,1>, <1,1>"), 1u) << pov;
  EXPECT_EQ(count_of(pov, "uv_indices { 2,\n    <0,1,2>, <0,2,3>"), 1u);
  // Two layers on the quad (its decal and the planar one), none on the ground, which is not climbable;
  // the surface's own texture at the bottom, then the layers in the plant's order.
  EXPECT_EQ(count_of(pov, "image_map"), 2u);
  const auto surface = pov.find("texture { GB_Surface }"), a = pov.find("png \"a.png\""), b = pov.find("png \"b.png\"");
  ASSERT_NE(b, std::string::npos);
  EXPECT_LT(surface, a);
  EXPECT_LT(a, b);
  EXPECT_NE(pov.find("pigment { uv_mapping image_map { png \"a.png\" once interpolate 2 } }"), std::string::npos);
  // The planar matrix in POV-Ray's coordinates: rows u_axis, v_axis, the normal and the origin, z negated.
  EXPECT_NE(pov.find("matrix <2,0,-1, 0,2,0, -0.447"), std::string::npos) << pov;
  EXPECT_NE(pov.find(", -1,0,-0.5>"), std::string::npos);
  // Without the plant the scene is as it always was: no layers, no texture coordinates.
  o.draw_plant = false;
  write_pov((dir / "bare.pov").string(), scene, p, o);
  const std::string bare = read_file(dir / "bare.pov");
  EXPECT_EQ(count_of(bare, "image_map"), 0u);
  EXPECT_EQ(count_of(bare, "uv_vectors"), 0u);
}

TEST(PovRender, UvDecalFollowsTheMeshTextureCoordinates) {
  ASSERT_FALSE(find_povray().empty()) << "povray is not installed (scripts/install-deps installs it)";
  const auto dir = test::temp_dir("decal_uv");
  write_decal_png(dir / "vine.png");
  const Scene scene = uv_quad_scene();
  Plant plant = tiny_plant();  // its stem stands in front of the quad, and must not be drawn
  plant.decals = {uv_decal("vine.png", 0)};
  RenderOptions o;
  o.width = 160;
  o.height = 120;
  const RenderResult with = render_plant(scene, plant, (dir / "with.pov").string(), (dir / "with.png").string(), o);
  ASSERT_TRUE(with.ok()) << with.message;
  EXPECT_TRUE(with.warnings.empty()) << with.warnings.front();
  o.draw_plant = false;
  const RenderResult bare = render_plant(scene, plant, (dir / "bare.pov").string(), (dir / "bare.png").string(), o);
  ASSERT_TRUE(bare.ok()) << bare.message;
  const Image a = load_png(with.png), b = load_png(bare.png);
  auto at = [&](const Image& im, const glm::vec3& p) {
    return rgb_at(im, pixel_of(scene.camera, o.width, o.height, p));
  };
  // The image's red top-left quadrant lands where the mirrored coordinates put it: the quad's top right.
  const glm::vec3 red_spot(0.5f, 1.5f, 0.0f);
  EXPECT_TRUE(is_red(at(a, red_spot))) << show(at(a, red_spot));
  EXPECT_FALSE(is_red(at(b, red_spot))) << show(at(b, red_spot));
  // Where the image is transparent the surface shows as it does without the decal: the top left (a
  // projection ignoring the coordinates would put the red there) and the bottom (v flipped would).
  for (const glm::vec3 p : {glm::vec3(-0.5f, 1.5f, 0.0f), glm::vec3(0.5f, 0.5f, 0.0f), glm::vec3(-0.5f, 0.5f, 0.0f)})
    EXPECT_LE(max_difference(at(a, p), at(b, p)), 12) << show(at(a, p)) << " against " << show(at(b, p));
  // The stem is not drawn over it.
  const glm::vec3 stem(0.0f, 0.5f, 0.2f);
  EXPECT_LE(max_difference(at(a, stem), at(b, stem)), 12) << show(at(a, stem)) << " against " << show(at(b, stem));
}

TEST(PovRender, PlanarDecalIsProjectedOntoTheClimbableMeshes) {
  ASSERT_FALSE(find_povray().empty()) << "povray is not installed (scripts/install-deps installs it)";
  const auto dir = test::temp_dir("decal_planar");
  write_decal_png(dir / "vine.png");
  const Scene scene = planar_scene();
  Plant plant;
  plant.decals = {tilted_planar_decal("vine.png")};
  RenderOptions o;
  o.width = 160;
  o.height = 120;
  const RenderResult with = render_plant(scene, plant, (dir / "with.pov").string(), (dir / "with.png").string(), o);
  ASSERT_TRUE(with.ok()) << with.message;
  EXPECT_TRUE(with.warnings.empty()) << with.warnings.front();
  o.draw_plant = false;
  const RenderResult bare = render_plant(scene, plant, (dir / "bare.pov").string(), (dir / "bare.png").string(), o);
  ASSERT_TRUE(bare.ok()) << bare.message;
  const Image a = load_png(with.png), b = load_png(bare.png);
  auto at = [&](const Image& im, const glm::vec3& p) {
    return rgb_at(im, pixel_of(scene.camera, o.width, o.height, p));
  };
  // On the wall's face, u = (x + 0.75) / 2.5 and v = y / 2: x = 0.25 is u = 0.4, in the red quadrant.
  const glm::vec3 red_spot(0.25f, 1.5f, -0.5f);
  EXPECT_TRUE(is_red(at(a, red_spot))) << show(at(a, red_spot));
  EXPECT_FALSE(is_red(at(b, red_spot))) << show(at(b, red_spot));
  // The surface shows at u = -0.1 (outside the image; with z mirrored it would be u = 0.1, red), at
  // u = 0.7 and at v = 0.25 (the transparent parts), and on the post, which is not climbable (were it
  // painted, u = 0.28 and v = 0.75 there: red).
  for (const glm::vec3 p : {glm::vec3(-1.0f, 1.5f, -0.5f), glm::vec3(1.0f, 1.5f, -0.5f), glm::vec3(0.25f, 0.5f, -0.5f),
                            glm::vec3(-0.3f, 1.5f, 0.0f)})
    EXPECT_LE(max_difference(at(a, p), at(b, p)), 12) << show(at(a, p)) << " against " << show(at(b, p));
}

TEST(PovRender, DecalsThatCannotBeDrawnFailTheRenderWithTheReason) {
  const auto dir = test::temp_dir("decal_fail");
  Plant p = tiny_plant();
  p.decals = {uv_decal("vine.png", 0)};
  RenderOptions o;
  o.width = 32;
  o.height = 24;
  // The image is not beside the render: recorded as failed, naming the file, without running POV-Ray
  // (and an earlier render's image is not left to pass for this one's).
  test::write_text(dir / "a.png", "an earlier render");
  RenderResult r = render_plant(uv_quad_scene(), p, (dir / "a.pov").string(), (dir / "a.png").string(), o);
  EXPECT_EQ(r.status, "failed");
  EXPECT_NE(r.message.find((dir / "vine.png").string() + " is missing"), std::string::npos) << r.message;
  EXPECT_FALSE(std::filesystem::exists(dir / "a.png"));
  // The image is there, but the scene's mesh has no texture coordinates (tiny_scene's wall).
  write_decal_png(dir / "vine.png");
  r = render_plant(tiny_scene(), p, (dir / "b.pov").string(), (dir / "b.png").string(), o);
  EXPECT_EQ(r.status, "failed");
  EXPECT_NE(r.message.find("decal 0 (vine.png) follows the texture coordinates of mesh 0 ('wall'), which has none"),
            std::string::npos)
      << r.message;
  EXPECT_NE(test::error_of([&] { write_pov((dir / "c.pov").string(), tiny_scene(), p, o); }).find("which has none"),
            std::string::npos);
  // A mesh the scene does not have, and a planar decal whose axes span no plane.
  p.decals[0].mesh = 3;
  EXPECT_NE(decal_problem(tiny_scene(), p).find("is on mesh 3, but scene 'tiny' has 1 meshes"), std::string::npos);
  p.decals[0] = tilted_planar_decal("vine.png");
  p.decals[0].v_axis = 2.0f * p.decals[0].u_axis;
  EXPECT_NE(decal_problem(tiny_scene(), p).find("span no plane"), std::string::npos);
  // Drawn without the plant, its decals are not drawn either, and nothing they name is needed.
  p.decals[0].image = "gone.png";
  o.draw_plant = false;
  if (!find_povray().empty()) {
    r = render_plant(tiny_scene(), p, (dir / "d.pov").string(), (dir / "d.png").string(), o);
    EXPECT_TRUE(r.ok()) << r.message;
  }
}

TEST(PovRender, TinySceneRendersWithThePlantInFrameAndNoWarnings) {
  ASSERT_FALSE(find_povray().empty()) << "povray is not installed (scripts/install-deps installs it)";
  const auto dir = test::temp_dir("render");
  RenderOptions o;
  o.width = 160;
  o.height = 120;
  const RenderResult with =
      render_plant(tiny_scene(), tiny_plant(), (dir / "with.pov").string(), (dir / "with.png").string(), o);
  ASSERT_TRUE(with.ok()) << with.message;
  EXPECT_TRUE(with.warnings.empty()) << with.warnings.front();
  EXPECT_GT(with.wall_s, 0.0);
  o.draw_plant = false;
  const RenderResult without =
      render_plant(tiny_scene(), tiny_plant(), (dir / "without.pov").string(), (dir / "without.png").string(), o);
  ASSERT_TRUE(without.ok()) << without.message;
  const Image a = load_png(with.png), b = load_png(without.png);
  ASSERT_EQ(a.w, 160);
  ASSERT_EQ(a.h, 120);
  EXPECT_GT(luminance_variance(a), 50.0);  // not blank
  // The plant is in frame: pixels differ from the render without it, around the image's centre column
  // (the stem stands at x = 0, straight in front of the camera).
  std::size_t differ = 0, centre = 0;
  for (int y = 0; y < a.h; ++y)
    for (int x = 0; x < a.w; ++x) {
      const std::size_t i = 3 * (static_cast<std::size_t>(y) * a.w + x);
      int d = 0;
      for (int c = 0; c < 3; ++c) d += std::abs(a.rgb[i + c] - b.rgb[i + c]);
      if (d > 30) {
        ++differ;
        if (std::abs(x - a.w / 2) < 6) ++centre;
      }
    }
  EXPECT_GT(differ, 200u);
  EXPECT_GT(centre, 20u);
  EXPECT_LT(differ, static_cast<std::size_t>(a.w * a.h / 2));
}

TEST(PovRender, FailuresAreRecordedWithPovRaysMessage) {
  const auto dir = test::temp_dir("render_fail");
  test::write_text(dir / "bad.pov", "#version 3.7;\nsphere { <0,0,0>, 1 \n");
  RenderOptions o;
  o.width = 32;
  o.height = 24;
  const RenderResult r = run_povray((dir / "bad.pov").string(), (dir / "bad.png").string(), o);
  EXPECT_EQ(r.status, "failed");
  EXPECT_NE(r.message.find("POV-Ray failed on"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("Parse Error"), std::string::npos) << r.message;
  // No povray on PATH: a clear status, not an exception.
  const std::string path = std::getenv("PATH");
  setenv("PATH", dir.c_str(), 1);
  const RenderResult missing = run_povray((dir / "bad.pov").string(), (dir / "bad.png").string(), o);
  setenv("PATH", path.c_str(), 1);
  EXPECT_EQ(missing.status, "no_povray");
  EXPECT_NE(missing.message.find("install-deps"), std::string::npos);
}

// A hostile scene file: names with line breaks, written into `//` comments of the .pov file, would end
// the comment and run what follows as POV-Ray directives.
TEST(PovWriter, NamesWithLineBreaksStayInsideTheirComments) {
  const auto dir = test::temp_dir("pov_inject");
  const std::string attack = "x'\n#fopen F \"" + (dir / "pwned.txt").string() + "\" write\n#fclose F\n// ";
  Scene scene = tiny_scene();
  scene.name = attack;
  scene.meshes[0].name = attack;
  write_pov((dir / "a.pov").string(), scene, tiny_plant(), RenderOptions{});
  const std::string text = read_file(dir / "a.pov");
  EXPECT_EQ(text.find("\n#fopen"), std::string::npos);
  EXPECT_EQ(text.find("\n#fclose"), std::string::npos);
  EXPECT_NE(text.find("// growbench render: scene 'x'\\x0a#fopen F"), std::string::npos) << text.substr(0, 300);
  EXPECT_NE(text.find("// scene mesh 'x'\\x0a#fopen F"), std::string::npos);
  if (!find_povray().empty()) {
    RenderOptions o;
    o.width = 32;
    o.height = 24;
    const RenderResult r = run_povray((dir / "a.pov").string(), (dir / "a.png").string(), o);
    EXPECT_TRUE(r.ok()) << r.message;
    EXPECT_FALSE(std::filesystem::exists(dir / "pwned.txt"));
  }
}

// Were a directive to escape anyway, POV-Ray runs confined to writing its image: a scene file that opens
// a file for writing fails to render and writes nothing, in the render's folder or anywhere else.
TEST(PovRender, PovRayWritesNothingButItsImage) {
  ASSERT_FALSE(find_povray().empty()) << "povray is not installed (scripts/install-deps installs it)";
  if (landlock_abi() == 0) GTEST_SKIP() << "this kernel has no Landlock: POV-Ray runs unconfined";
  const auto dir = test::temp_dir("pov_confined");
  const auto outside = test::temp_dir("pov_confined_outside");
  RenderOptions o;
  o.width = 32;
  o.height = 24;
  for (const std::filesystem::path& target : {dir / "here.txt", outside / "tmp.txt"}) {
    test::write_text(dir / "w.pov", "#version 3.7;\n#fopen F \"" + target.string() +
                                        "\" write\n#write (F, \"x\")\n#fclose F\n"
                                        "camera { location <0,0,-3> look_at 0 }\nsphere { 0, 1 pigment { rgb 1 } }\n");
    const RenderResult r = run_povray((dir / "w.pov").string(), (dir / "w.png").string(), o);
    EXPECT_FALSE(std::filesystem::exists(target)) << target;
    EXPECT_EQ(r.status, "failed") << target;
    EXPECT_FALSE(std::filesystem::exists(dir / "w.png"));
  }
  // The same scene without the write renders, and POV-Ray's private folder is gone after.
  test::write_text(dir / "ok.pov",
                   "#version 3.7;\ncamera { location <0,0,-3> look_at 0 }\n"
                   "light_source { <0,5,-5> rgb 1 }\nsphere { 0, 1 pigment { rgb 1 } }\n");
  const RenderResult ok = run_povray((dir / "ok.pov").string(), (dir / "ok.png").string(), o);
  EXPECT_TRUE(ok.ok()) << ok.message;
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "ok.png"));
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_NE(e.path().filename().string().rfind(".povray-", 0), 0u) << e.path();
}

TEST(PovRender, ADecalImageNameMustStayInTheRendersFolder) {
  const auto dir = test::temp_dir("decal_name");
  RenderOptions o;
  o.width = 32;
  o.height = 24;
  for (const std::string name : {"../vine.png", "/tmp/vine.png", "a\"b.png", "a\nb.png", "a\\b.png", ""}) {
    Plant p = tiny_plant();
    p.decals = {uv_decal(name, 0)};
    const RenderResult r = render_plant(uv_quad_scene(), p, (dir / "a.pov").string(), (dir / "a.png").string(), o);
    EXPECT_EQ(r.status, "failed") << name;
    const bool said = r.message.find("decal 0: its image") != std::string::npos &&
                      (r.message.find("is not a plain file name inside the render's directory") != std::string::npos ||
                       r.message.find("has a control character") != std::string::npos);
    EXPECT_TRUE(said) << r.message;
  }
}

TEST(RenderGrid, LabelsCellsAndMarksMissingOnes) {
  const auto dir = test::temp_dir("grid");
  RenderOptions o;
  o.width = 80;
  o.height = 60;
  const RenderResult r =
      render_plant(tiny_scene(), tiny_plant(), (dir / "a.pov").string(), (dir / "a.png").string(), o);
  ASSERT_TRUE(r.ok()) << r.message;
  const GridLayout lay = write_grid((dir / "grid.png").string(), "title", {"alpha", "beta"}, {"s1", "s2", "s3"},
                                    {{r.png, r.png, ""}, {r.png, "", (dir / "missing.png").string()}},
                                    {{"", "", "timeout"}}, {{"", "degenerate"}}, 100);
  const Image g = load_png((dir / "grid.png").string());
  EXPECT_EQ(g.w, lay.width);
  EXPECT_EQ(g.h, lay.height);
  // Printed 7 in wide, the labels are 8 pt or more.
  EXPECT_GE(lay.label_px * kGridPrintWidthIn * 72.0 / lay.width, kGridMinLabelPt - 1e-9);
  ASSERT_EQ(lay.cells.size(), 6u);  // row-major, with where each image is
  EXPECT_EQ(lay.cells[1].row, 0);
  EXPECT_EQ(lay.cells[1].col, 1);
  EXPECT_EQ(lay.cells[1].x - lay.cells[0].x, 100 + 6);  // cells of 100 px with 6 px between
  EXPECT_EQ(lay.cells[3].y - lay.cells[0].y, 75 + 6);   // two rows of 4:3 cells
  EXPECT_EQ(lay.height, lay.cells[3].y + 75 + 6 + 6);   // a pad below each row, and the margin
  EXPECT_GT(luminance_variance(g), 100.0);
  // The degenerate plant's cell (row 0, column 1) carries a red band at its top; its neighbour does not.
  auto pixel = [&](int x, int y) { return g.rgb[static_cast<std::size_t>(3 * (y * g.w + x))]; };
  auto greenish = [&](int x, int y) { return g.rgb[static_cast<std::size_t>(3 * (y * g.w + x) + 1)]; };
  const int y = lay.cells[1].y + 2, x_badged = lay.cells[1].x + 2, x_plain = lay.cells[0].x + 2;
  EXPECT_GT(pixel(x_badged, y), 150);
  EXPECT_LT(greenish(x_badged, y), 80);
  EXPECT_FALSE(pixel(x_plain, y) > 150 && greenish(x_plain, y) < 80);
  // A wider grid has larger labels, still 8 pt at 7 in.
  const GridLayout wide = write_grid((dir / "wide.png").string(), "t", {"a"}, std::vector<std::string>(12, "s"),
                                     {std::vector<std::string>(12, r.png)});
  EXPECT_GT(wide.label_px, lay.label_px);
  EXPECT_GE(wide.label_px * kGridPrintWidthIn * 72.0 / wide.width, kGridMinLabelPt - 1e-9);
  // The captioned form: each image under its own caption, four to a row.
  const GridLayout cap = write_captioned_grid((dir / "cap.png").string(), "scene", {"a", "b", "c", "d", "e"},
                                              std::vector<std::string>(5, r.png), {}, {}, 4, 100);
  ASSERT_EQ(cap.cells.size(), 5u);
  EXPECT_EQ(cap.cells[4].row, 1);
  EXPECT_EQ(cap.cells[4].col, 0);
  EXPECT_EQ(load_png((dir / "cap.png").string()).w, cap.width);
}

TEST(RenderCli, RunRendersThePlantAndItsGrowthFrames) {
  const auto dir = test::temp_dir("cli_render");
  const auto r = test::run_growbench(
      "run -q -a spacecol -s wall --set point_count=800 --max-steps 30 --frames 10 "
      "--render preview -o " +
      dir.string());
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream in(dir / "record.json");
  const auto rec = nlohmann::json::parse(in);
  EXPECT_EQ(rec["render"]["status"], "ok");
  EXPECT_EQ(rec["render"]["png"], "render.png");
  EXPECT_TRUE(rec["render"]["warnings"].empty());
  EXPECT_TRUE(std::filesystem::exists(dir / "render.png"));
  // Frames at steps 10, 20, 30 (the last step is 30 too): three snapshots, three images.
  EXPECT_EQ(rec["frames"]["count"], 3);
  for (const char* f : {"frames/step_000010.png", "frames/step_000020.png", "frames/step_000030.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  EXPECT_TRUE(rec["phases"]["growth"].contains("frame_capture_wall_s"));
  if (!find_povray().empty() && std::system("command -v ffmpeg > /dev/null") == 0) {
    EXPECT_EQ(rec["animation"]["status"], "ok") << rec["animation"].dump();
    EXPECT_TRUE(std::filesystem::exists(dir / "animation.mp4"));
  }
  // Rendering again (another quality) rewrites the render record; a directory that is neither a run
  // nor a suite is a clear error.
  const auto again = test::run_growbench("render -q --width 64 --height 48 " + dir.string());
  EXPECT_EQ(again.status, 0) << again.out;
  const auto bad = test::run_growbench("render " + test::temp_dir("cli_render_empty").string());
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.out.find("neither a suite results directory"), std::string::npos) << bad.out;
}

TEST(RenderCli, BadRenderOptionsAreRefusedBeforeTheTrialNamingTheOption) {
  const auto dir = test::temp_dir("cli_render_bad");
  const std::string run = "run -q -a spacecol -s wall --set point_count=300 --max-steps 20 -o " + dir.string();
  for (const auto& [args, option] :
       std::vector<std::pair<std::string, std::string>>{{" --render preview --camera fish", "--camera"},
                                                        {" --render preview --backdrop moon", "--backdrop"},
                                                        {" --render preview --turntable 0", "--turntable"},
                                                        {" --render preview --turntable -2", "--turntable"},
                                                        {" --render preview --dof", "--dof"},
                                                        {" --turntable 3", "--render"}}) {
    const auto r = test::run_growbench(run + args);
    EXPECT_EQ(r.status, 2) << args << ": " << r.out;
    EXPECT_NE(r.out.find(option), std::string::npos) << args << ": " << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir / "record.json")) << args << ": the plant grew first";
  }
  const auto grown = test::run_growbench(run);
  ASSERT_EQ(grown.status, 0) << grown.out;
  for (const auto& [args, option] : std::vector<std::pair<std::string, std::string>>{
           {"--camera fish", "--camera"}, {"--turntable 0", "--turntable"}, {"--dof", "--dof"}}) {
    const auto r = test::run_growbench("render -q " + args + " " + dir.string());
    EXPECT_EQ(r.status, 2) << args << ": " << r.out;
    EXPECT_NE(r.out.find(option), std::string::npos) << args << ": " << r.out;
  }
}

TEST(RenderCli, TurntableRendersFramesAroundThePlantAndItsVideo) {
  const auto dir = test::temp_dir("cli_turntable");
  const auto run =
      test::run_growbench("run -q -a spacecol -s wall --set point_count=300 --max-steps 20 -o " + dir.string());
  ASSERT_EQ(run.status, 0) << run.out;
  const auto r = test::run_growbench("render --width 64 --height 48 --turntable 4 --backdrop studio " + dir.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("turntable/frame_0003.png: ok"), std::string::npos) << r.out;  // a progress line per frame
  std::set<std::string> cameras;
  for (int k = 0; k < 4; ++k) {
    const auto frame = dir / "turntable" / fmt::format("frame_{:04d}", k);
    EXPECT_TRUE(std::filesystem::exists(fs_concat(frame, ".png"))) << frame;
    const std::string pov = read_file(fs_concat(frame, ".pov"));
    cameras.insert(pov.substr(pov.find("camera {"), pov.find('\n', pov.find("camera {")) - pov.find("camera {")));
    EXPECT_NE(pov.find("GB_Studio"), std::string::npos);
  }
  EXPECT_EQ(cameras.size(), 4u);
  std::ifstream in(dir / "record.json");
  const auto rec = nlohmann::json::parse(in);
  EXPECT_EQ(rec["turntable"]["frames"], 4);
  EXPECT_EQ(rec["render"]["backdrop"], "studio");
  EXPECT_TRUE(rec["render"]["camera"] == "fitted" || rec["render"]["camera"] == "scene") << rec["render"].dump();
  if (std::system("command -v ffmpeg > /dev/null") == 0) {
    EXPECT_EQ(rec["turntable"]["status"], "ok") << rec["turntable"].dump();
    EXPECT_TRUE(std::filesystem::exists(dir / "turntable.mp4"));
  }
  // A shorter turntable leaves none of the longer one's frames behind.
  const auto again = test::run_growbench("render -q --width 64 --height 48 --turntable 2 " + dir.string());
  ASSERT_EQ(again.status, 0) << again.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "turntable" / "frame_0001.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "turntable" / "frame_0002.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "turntable" / "frame_0003.pov"));
}

TEST(RenderCli, DecalImagesAreReadBesideTheirSnapshotsAndAreNotAnimationFrames) {
  const auto dir = test::temp_dir("cli_render_decals");
  const auto run = test::run_growbench(
      "run -q -a spacecol -s wall --set point_count=300 --max-steps 20 --frames 10 -o " + dir.string());
  ASSERT_EQ(run.status, 0) << run.out;
  // Decals on the plant and its frames, as an algorithm that paints them leaves them: the run's image
  // beside plant.gbplant, each frame's as step_NNNNNN.IMAGE beside its snapshot.
  SurfaceDecal d = tilted_planar_decal("vine.png");
  Plant plant = read_plant_snapshot((dir / "plant.gbplant").string());
  plant.decals = {d};
  write_plant_snapshot((dir / "plant.gbplant").string(), plant);
  write_decal_png(dir / "vine.png");
  std::size_t frames = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir / "frames")) {
    if (e.path().extension() != ".gbplant") continue;
    const std::string prefix = e.path().stem().string() + ".";
    Plant f = read_plant_snapshot(e.path().string());
    f.decals = {d};
    write_plant_snapshot(e.path().string(), f, prefix);
    write_decal_png(dir / "frames" / (prefix + "vine.png"));
    ++frames;
  }
  ASSERT_GE(frames, 2u);
  RenderDirOptions ro;
  ro.render.width = 64;
  ro.render.height = 48;
  ro.quiet = true;
  ro.turntable = 2;  // its frames, in turntable/, read the run's decal image beside plant.gbplant
  const RenderSummary summary = render_directory_record(dir.string(), ro);
  EXPECT_EQ(summary.failed, 0u);
  EXPECT_EQ(summary.ok, frames + 1 + 2);
  EXPECT_NE(read_file(dir / "turntable" / "frame_0001.pov").find("png \"vine.png\""), std::string::npos);
  EXPECT_EQ(summary.warnings, 0u);
  EXPECT_NE(read_file(dir / "frames" / "step_000010.pov").find("png \"step_000010.vine.png\""), std::string::npos);
  EXPECT_NE(read_file(dir / "render.pov").find("png \"vine.png\""), std::string::npos);
  std::ifstream in(dir / "record.json");
  const auto rec = nlohmann::json::parse(in);
  EXPECT_EQ(rec["render"]["status"], "ok") << rec["render"].dump();
  if (std::system("command -v ffmpeg > /dev/null && command -v ffprobe > /dev/null") != 0) return;
  // The animation is made of the rendered frames alone, not of the decal images beside them.
  EXPECT_EQ(rec["animation"]["status"], "ok") << rec["animation"].dump();
  EXPECT_EQ(rec["animation"]["frames"], frames);
  const std::string probe = (dir / "probe.txt").string();
  ASSERT_EQ(std::system(("ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames,width "
                         "-of csv=p=0 " +
                         (dir / "animation.mp4").string() + " > " + probe)
                            .c_str()),
            0);
  EXPECT_EQ(read_file(probe), "64," + std::to_string(frames) + "\n");
}

}  // namespace
}  // namespace growbench
