// The standard scenes, built in code. Every solid is its own closed mesh (the SDF is the union of their
// level sets, so touching or overlapping parts need no boolean meshing). Solids that stand on the
// ground reach 5 cm into it so that no faces are coplanar.
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/random.hpp"
#include "scenes/geometry.hpp"
#include "scenes/scene_library.hpp"

namespace growbench {
namespace {

constexpr float kSink = 0.05f;  // how far standing solids reach below y = 0

TriangleMesh ground(float half) {
  auto g = geom::make_box("ground", {-half, -0.1f, -half}, {half, 0.0f, half});
  g.climbable = false;
  return g;
}

Shape box_shape(const glm::vec3& lo, const glm::vec3& hi) {
  Shape s;
  s.kind = Shape::Kind::Box;
  s.min = lo;
  s.max = hi;
  return s;
}

Shape ellipsoid_shape(const glm::vec3& c, const glm::vec3& r) {
  Shape s;
  s.kind = Shape::Kind::Sphere;
  s.center = c;
  s.radii = r;
  return s;
}

// n seeds spread evenly along a line from a to b (centred when n == 1).
void seeds_along(Scene& s, int n, const glm::vec3& a, const glm::vec3& b) {
  for (int i = 0; i < n; ++i) {
    const float t = n == 1 ? 0.5f : static_cast<float>(i) / static_cast<float>(n - 1);
    s.seeds.push_back({glm::mix(a, b, t), {0, 1, 0}, 0});
  }
}

// n seeds on a circle of radius r around (cx, cz) at height y.
void seeds_around(Scene& s, int n, float cx, float cz, float r, float y, float phase = 0.3f) {
  for (int i = 0; i < n; ++i) {
    const float a = phase + 2.0f * std::numbers::pi_v<float> * static_cast<float>(i) / static_cast<float>(n);
    s.seeds.push_back({{cx + r * std::cos(a), y, cz + r * std::sin(a)}, {0, 1, 0}, 0});
  }
}

Scene build_wall(const Params& p) {
  const auto w = static_cast<float>(p.real("width")), h = static_cast<float>(p.real("height")),
             t = static_cast<float>(p.real("thickness"));
  Scene s;
  s.name = "wall";
  s.meshes.push_back(ground(std::max(w, h) + 1.0f));
  s.meshes.push_back(geom::make_box("wall", {-w / 2, -kSink, -t / 2}, {w / 2, h, t / 2}));
  seeds_along(s, static_cast<int>(p.integer("seeds")), {-w / 3, 0.02f, t / 2 + 0.03f}, {w / 3, 0.02f, t / 2 + 0.03f});
  s.envelope = box_shape({-w / 2, 0.0f, t / 2}, {w / 2, h, t / 2 + 0.5f});
  s.camera = {{0.0f, 0.55f * h, 1.9f * std::max(w, h) + 0.5f}, {0.0f, 0.45f * h, 0.0f}, 45.0f};
  return s;
}

Scene build_facade(const Params& p) {
  const auto w = static_cast<float>(p.real("width")), h = static_cast<float>(p.real("height"));
  const int windows = static_cast<int>(p.integer("windows"));
  const float t = 0.25f, sill = 0.35f * h, lintel = 0.75f * h, win_w = std::min(0.9f, 0.6f * w / windows);
  Scene s;
  s.name = "facade";
  s.meshes.push_back(ground(std::max(w, h) + 1.0f));
  s.meshes.push_back(geom::make_box("facade_base", {-w / 2, -kSink, -t / 2}, {w / 2, sill, t / 2}));
  s.meshes.push_back(geom::make_box("facade_top", {-w / 2, lintel, -t / 2}, {w / 2, h, t / 2}));
  // Piers between the window openings; the bands above overlap them slightly (no coplanar faces).
  float x = -w / 2;
  for (int i = 0; i <= windows; ++i) {
    const float centre = -w / 2 + w * (static_cast<float>(i) + 0.5f) / static_cast<float>(windows);
    const float next = i < windows ? centre - win_w / 2 : w / 2;
    s.meshes.push_back(
        geom::make_box(fmt::format("facade_pier{}", i), {x, sill - 0.01f, -t / 2}, {next, lintel + 0.01f, t / 2}));
    x = centre + win_w / 2;
  }
  // A ledge under the upper band.
  s.meshes.push_back(geom::make_box("facade_ledge", {-w / 2 - 0.1f, lintel - 0.12f, t / 2 - 0.02f},
                                    {w / 2 + 0.1f, lintel - 0.04f, t / 2 + 0.25f}));
  seeds_along(s, static_cast<int>(p.integer("seeds")), {-w / 3, 0.02f, t / 2 + 0.03f}, {w / 3, 0.02f, t / 2 + 0.03f});
  s.envelope = box_shape({-w / 2, 0.0f, t / 2}, {w / 2, h, t / 2 + 0.5f});
  s.camera = {{0.0f, 0.55f * h, 1.9f * std::max(w, h) + 0.5f}, {0.0f, 0.45f * h, 0.0f}, 45.0f};
  return s;
}

Scene build_column(const Params& p) {
  const auto r = static_cast<float>(p.real("radius")), h = static_cast<float>(p.real("height"));
  Scene s;
  s.name = "column";
  s.meshes.push_back(ground(h));
  s.meshes.push_back(geom::make_cylinder("column", {0, -kSink, 0}, {0, h, 0}, r, r, 48));
  seeds_around(s, static_cast<int>(p.integer("seeds")), 0.0f, 0.0f, r + 0.03f, 0.02f);
  s.envelope = box_shape({-r - 0.4f, 0.0f, -r - 0.4f}, {r + 0.4f, h, r + 0.4f});
  s.camera = {{0.0f, 0.55f * h, 2.2f * h}, {0.0f, 0.45f * h, 0.0f}, 40.0f};
  return s;
}

Scene build_corner(const Params& p) {
  const auto w = static_cast<float>(p.real("width")), h = static_cast<float>(p.real("height")),
             o = static_cast<float>(p.real("overhang"));
  const float t = 0.2f;
  Scene s;
  s.name = "corner";
  s.meshes.push_back(ground(w + 1.0f));
  s.meshes.push_back(geom::make_box("wall_x", {-t, -kSink, -t}, {w, h, 0.0f}));
  s.meshes.push_back(geom::make_box("wall_z", {-t, -kSink, 0.0f - 0.01f}, {0.0f, h, w}));
  s.meshes.push_back(geom::make_box("roof", {-t - 0.05f, h - 0.02f, -t - 0.05f}, {w, h + 0.15f, o}));
  s.seeds.push_back({{0.04f, 0.02f, 0.04f}, {0, 1, 0}, 0});
  const int extra = static_cast<int>(p.integer("seeds")) - 1;
  for (int i = 0; i < extra; ++i) {
    const float d = w * static_cast<float>(i / 2 + 1) / static_cast<float>(extra / 2 + 2);
    s.seeds.push_back({i % 2 == 0 ? glm::vec3(d, 0.02f, 0.04f) : glm::vec3(0.04f, 0.02f, d), {0, 1, 0}, 0});
  }
  s.envelope = box_shape({0.0f, 0.0f, 0.0f}, {0.6f * w, h, 0.6f * w});
  s.light.direction = {0.6f, 1.0f, 0.8f};
  s.camera = {{1.45f * w + 1.0f, 0.6f * h, 1.45f * w + 1.0f}, {0.2f * w, 0.45f * h, 0.2f * w}, 45.0f};
  return s;
}

Scene build_pergola(const Params& p) {
  const auto w = static_cast<float>(p.real("width")), d = static_cast<float>(p.real("depth")),
             h = static_cast<float>(p.real("height"));
  const float post = 0.12f, beam = 0.15f;
  Scene s;
  s.name = "pergola";
  s.meshes.push_back(ground(std::max(w, d) + 1.0f));
  int k = 0;
  for (const float x : {-w / 2, w / 2})
    for (const float z : {-d / 2, d / 2})
      s.meshes.push_back(geom::make_box(fmt::format("post{}", k++), {x - post / 2, -kSink, z - post / 2},
                                        {x + post / 2, h + 0.01f, z + post / 2}));
  for (const float z : {-d / 2, d / 2})
    s.meshes.push_back(geom::make_box(fmt::format("beam{}", k++), {-w / 2 - 0.3f, h, z - post / 2},
                                      {w / 2 + 0.3f, h + beam, z + post / 2}));
  const int rafters = static_cast<int>(p.integer("rafters"));
  for (int i = 0; i < rafters; ++i) {
    const float x = -w / 2 + w * static_cast<float>(i) / static_cast<float>(rafters - 1);
    s.meshes.push_back(geom::make_box(fmt::format("rafter{}", i), {x - 0.04f, h + beam - 0.01f, -d / 2 - 0.3f},
                                      {x + 0.04f, h + beam + 0.1f, d / 2 + 0.3f}));
  }
  for (const float x : {-w / 2, w / 2})
    for (const float z : {-d / 2, d / 2}) {
      const glm::vec3 out = glm::normalize(glm::vec3(x, 0.0f, z));
      s.seeds.push_back({glm::vec3(x, 0.02f, z) + out * (post / 2 + 0.05f), {0, 1, 0}, 0});
    }
  s.envelope = box_shape({-w / 2 - 0.3f, 0.0f, -d / 2 - 0.3f}, {w / 2 + 0.3f, h + 0.5f, d / 2 + 0.3f});
  s.camera = {{0.9f * w + 1.5f, 0.9f * h, 1.3f * d + 2.5f}, {0.0f, 0.5f * h, 0.0f}, 45.0f};
  return s;
}

Scene build_boulder(const Params& p) {
  const auto r = static_cast<float>(p.real("radius")), rough = static_cast<float>(p.real("roughness"));
  Scene s;
  s.name = "boulder";
  s.meshes.push_back(ground(3.0f * r + 1.0f));
  TriangleMesh b = geom::make_icosphere("boulder", {0, 0, 0}, 1.0f, 4);
  // Deterministic bumps: a sum of a few random plane waves along random directions.
  Rng rng(0xB0u, 1);
  glm::vec3 dirs[6];
  float phases[6];
  for (int i = 0; i < 6; ++i) {
    dirs[i] = rng.unit_vector() * static_cast<float>(rng.uniform(1.5, 4.0));
    phases[i] = static_cast<float>(rng.uniform(0.0, 6.283));
  }
  const glm::vec3 centre(0.0f, 0.75f * r, 0.0f);
  // The rock's surface in the direction of unit vector u from its centre.
  auto surface = [&](const glm::vec3& u) {
    float bump = 0.0f;
    for (int i = 0; i < 6; ++i) bump += std::sin(glm::dot(dirs[i], u) + phases[i]) / 6.0f;
    return centre + u * r * (1.0f + rough * bump) * glm::vec3(1.0f, 0.85f, 1.0f);
  };
  for (auto& v : b.vertices) v = surface(v);
  s.meshes.push_back(std::move(b));
  // Seeds at the rock's foot, 3 cm out from where its surface is 2 cm above the ground (found by bisecting
  // the elevation below the equator, where the height rises with it): a climber starts at what it climbs.
  // They lean out (56 degrees from the vertical), so that a free-growing shoot rising from the seed passes
  // the bulge above it rather than growing into it.
  const int n = static_cast<int>(p.integer("seeds"));
  for (int i = 0; i < n; ++i) {
    const float a = 0.3f + 2.0f * std::numbers::pi_v<float> * static_cast<float>(i) / static_cast<float>(n);
    const glm::vec3 out(std::cos(a), 0.0f, std::sin(a));
    float lo = -0.5f * std::numbers::pi_v<float>, hi = 0.0f;
    for (int k = 0; k < 40; ++k) {
      const float mid = 0.5f * (lo + hi);
      (surface(std::cos(mid) * out + glm::vec3(0.0f, std::sin(mid), 0.0f)).y < 0.02f ? lo : hi) = mid;
    }
    const glm::vec3 foot = surface(std::cos(hi) * out + glm::vec3(0.0f, std::sin(hi), 0.0f));
    s.seeds.push_back({{foot.x + 0.03f * out.x, 0.02f, foot.z + 0.03f * out.z},
                       glm::normalize(glm::vec3(0.0f, 1.0f, 0.0f) + 1.5f * out),
                       0});
  }
  s.envelope = ellipsoid_shape(centre, glm::vec3(1.4f * r));
  s.camera = {{0.0f, 1.6f * r + 0.5f, 4.5f * r + 1.0f}, {0.0f, 0.6f * r, 0.0f}, 45.0f};
  return s;
}

Scene build_trunk(const Params& p) {
  const auto r = static_cast<float>(p.real("radius")), h = static_cast<float>(p.real("height"));
  Scene s;
  s.name = "trunk";
  s.meshes.push_back(ground(h));
  s.meshes.push_back(geom::make_cylinder("trunk", {0, -kSink, 0}, {0, h, 0}, r, 0.6f * r, 40));
  s.meshes.push_back(
      geom::make_cylinder("branch", {0, 0.55f * h, 0}, {0.4f * h, 0.85f * h, 0.05f}, 0.45f * r, 0.25f * r, 24));
  seeds_around(s, static_cast<int>(p.integer("seeds")), 0.0f, 0.0f, r + 0.04f, 0.02f);
  s.envelope = box_shape({-r - 0.5f, 0.0f, -r - 0.5f}, {0.4f * h + 0.5f, h, r + 0.5f});
  s.camera = {{0.3f * h, 0.55f * h, 2.0f * h + 1.0f}, {0.15f * h, 0.45f * h, 0.0f}, 45.0f};
  return s;
}

Scene build_envelope(const Params& p) {
  const auto r = static_cast<float>(p.real("crown_radius")), c = static_cast<float>(p.real("crown_height"));
  Scene s;
  s.name = "envelope";
  s.meshes.push_back(ground(r + 2.0f));
  s.seeds.push_back({{0, 0, 0}, {0, 1, 0}, 0});
  s.envelope = ellipsoid_shape({0.0f, c, 0.0f}, {r, 0.8f * r, r});
  s.camera = {{0.0f, 0.6f * (c + r), 2.4f * (c + r)}, {0.0f, 0.5f * (c + 0.8f * r), 0.0f}, 45.0f};
  return s;
}

}  // namespace

const std::vector<StandardScene>& standard_scenes() {
  static const std::vector<StandardScene> list = {
      {"wall",
       "a 3 x 2.5 m wall standing on the ground, seeds at its foot",
       {param::real("width", 3.0).range(0.5, 50).unit("m").doc("wall width (x)"),
        param::real("height", 2.5).range(0.5, 50).unit("m").doc("wall height (y)"),
        param::real("thickness", 0.2).range(0.02, 5).unit("m").doc("wall thickness (z)"),
        param::integer("seeds", 3).range(1, 64).doc("number of seeds along the wall's foot")},
       build_wall},
      {"facade",
       "a wall with window openings and a ledge",
       {param::real("width", 4.0).range(1, 50).unit("m").doc("facade width"),
        param::real("height", 3.0).range(1, 50).unit("m").doc("facade height"),
        param::integer("windows", 2).range(1, 16).doc("number of window openings"),
        param::integer("seeds", 3).range(1, 64).doc("number of seeds along the facade's foot")},
       build_facade},
      {"column",
       "a cylindrical pillar",
       {param::real("radius", 0.25).range(0.02, 10).unit("m").doc("column radius"),
        param::real("height", 3.0).range(0.5, 50).unit("m").doc("column height"),
        param::integer("seeds", 3).range(1, 64).doc("number of seeds around the base")},
       build_column},
      {"corner",
       "two walls meeting at a right angle under an overhanging roof",
       {param::real("width", 3.0).range(0.5, 50).unit("m").doc("length of each wall"),
        param::real("height", 2.6).range(0.5, 50).unit("m").doc("wall height"),
        param::real("overhang", 1.2).range(0, 20).unit("m").doc("how far the roof reaches out over the corner (z)"),
        param::integer("seeds", 3).range(1, 64).doc("number of seeds (the first in the corner)")},
       build_corner},
      {"pergola",
       "four posts, two beams and rafters",
       {param::real("width", 2.4).range(0.5, 50).unit("m").doc("distance between posts along x"),
        param::real("depth", 1.6).range(0.5, 50).unit("m").doc("distance between posts along z"),
        param::real("height", 2.4).range(0.5, 50).unit("m").doc("post height"),
        param::integer("rafters", 6).range(2, 64).doc("number of rafters")},
       build_pergola},
      {"boulder",
       "a noisy rock on the ground",
       {param::real("radius", 1.0).range(0.1, 20).unit("m").doc("rock radius"),
        param::real("roughness", 0.15).range(0, 0.5).doc("relative bump height"),
        param::integer("seeds", 3).range(1, 64).doc("number of seeds around the rock")},
       build_boulder},
      {"trunk",
       "a tree trunk with one branch",
       {param::real("radius", 0.3).range(0.05, 5).unit("m").doc("trunk radius at the base"),
        param::real("height", 3.5).range(0.5, 50).unit("m").doc("trunk height"),
        param::integer("seeds", 3).range(1, 64).doc("number of seeds around the base")},
       build_trunk},
      {"envelope",
       "ground and a crown envelope, nothing to climb (free-growing trees)",
       {param::real("crown_radius", 1.2).range(0.1, 50).unit("m").doc("horizontal radius of the ellipsoidal crown"),
        param::real("crown_height", 2.2).range(0.2, 100).unit("m").doc("height of the crown's centre")},
       build_envelope},
  };
  return list;
}

const std::vector<ParamSpec>& mesh_scene_params() {
  static const std::vector<ParamSpec> specs = {
      param::real("size", 2.0)
          .range(0.0, 1000)
          .unit("m")
          .doc("scale the mesh so its largest extent is this (0 keeps the file's units and placement)"),
      param::boolean("ground", true)
          .doc("a ground slab under the mesh (not climbable), where shoots that fall or hang come to rest, as on the "
               "floor every render shows; false: the mesh alone"),
  };
  return specs;
}

}  // namespace growbench
