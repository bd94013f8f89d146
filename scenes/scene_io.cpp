// Loading scenes: standard scenes by name, scene JSON files (validated, errors name the JSON path),
// and OBJ meshes as scenes (mesh:PATH, or mesh:NAME for a mesh the repository carries).
#include <algorithm>
#include <filesystem>
#include <limits>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tiny_obj_loader.h>

#include "core/data_path.hpp"
#include "core/json_util.hpp"
#include "core/utf8.hpp"
#include "scenes/geometry.hpp"
#include "scenes/obj_check.hpp"
#include "scenes/scene_library.hpp"

namespace growbench {
namespace fs = std::filesystem;
using nlohmann::json;

bool is_mesh_name(const std::string& ref) {
  return !ref.empty() && ref.find('/') == std::string::npos && !fs::path(ref).has_extension();
}

std::vector<std::string> bundled_meshes() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(data_path("scenes/meshes"), ec))
    if (e.path().extension() == ".obj") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string mesh_path(const std::string& ref) {
  if (!is_mesh_name(ref)) return ref;
  const fs::path p = fs::path(data_path("scenes/meshes")) / (ref + ".obj");
  if (file_problem(p.string()).empty()) return p.string();
  const std::vector<std::string> names = bundled_meshes();
  std::string near = closest_match(ref, names);
  for (const auto& n : names)  // "bunny" means the Stanford bunny
    if (near.empty() && n.find(ref) != std::string::npos) near = n;
  throw InputError(fmt::format("unknown mesh '{}'{}; expected a bundled mesh ({}) or a path to an OBJ file", ref,
                               near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near),
                               names.empty() ? fmt::format("none found in {}", data_path("scenes/meshes"))
                                             : fmt::format("{}", fmt::join(names, ", "))));
}

TriangleMesh load_obj(const std::string& path) {
  if (const std::string why = file_problem(path, true); !why.empty())
    throw InputError(fmt::format("{}: {} (expected an OBJ file)", path, why));
  check_obj_text(path, read_text_file(path));
  tinyobj::ObjReaderConfig cfg;
  cfg.triangulate = true;
  cfg.vertex_color = false;
  cfg.mtl_search_path = fs::path(path).parent_path().string();
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, cfg)) {
    std::string msg = reader.Error();
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
    throw InputError(fmt::format("{}: not a readable OBJ file: {}", path, msg.empty() ? "parse failed" : msg));
  }
  const auto& attrib = reader.GetAttrib();
  TriangleMesh m;
  m.name = fs::path(path).stem().string();
  const std::size_t nv = attrib.vertices.size() / 3;
  m.vertices.reserve(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    const glm::vec3 v(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      throw InputError(fmt::format("{}: vertex {} has a non-finite coordinate", path, i + 1));
    m.vertices.push_back(v);
  }
  const std::size_t nt = attrib.texcoords.size() / 2;
  m.uvs.reserve(nt);
  for (std::size_t i = 0; i < nt; ++i) {
    const glm::vec2 uv(attrib.texcoords[2 * i], attrib.texcoords[2 * i + 1]);
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y))
      throw InputError(fmt::format("{}: texture coordinate (vt) {} is not finite", path, i + 1));
    m.uvs.push_back(uv);
  }
  // Texture coordinates are kept only when every face has them: a mesh half mapped has no mapping.
  bool every_face_uv = nt > 0;
  for (const auto& shape : reader.GetShapes()) {
    std::size_t offset = 0;
    for (const auto fv : shape.mesh.num_face_vertices) {
      if (fv == 3) {
        glm::uvec3 t, tt;
        for (int k = 0; k < 3; ++k) {
          const auto& corner = shape.mesh.indices[offset + static_cast<std::size_t>(k)];
          const int idx = corner.vertex_index;
          if (idx < 0 || static_cast<std::size_t>(idx) >= nv)
            throw InputError(fmt::format("{}: shape '{}' has a face with vertex index {} out of range (1..{})", path,
                                         shape.name, idx + 1, nv));
          t[k] = static_cast<unsigned>(idx);
          const int ti = corner.texcoord_index;
          if (ti >= 0 && static_cast<std::size_t>(ti) >= nt)
            throw InputError(fmt::format("{}: shape '{}' has a face with texture index {} out of range (1..{})", path,
                                         shape.name, ti + 1, nt));
          if (ti < 0) every_face_uv = false;
          tt[k] = ti < 0 ? 0u : static_cast<unsigned>(ti);
        }
        if (t.x != t.y && t.y != t.z && t.x != t.z) {
          m.triangles.push_back(t);
          if (every_face_uv) m.uv_triangles.push_back(tt);  // nothing to keep for a mesh without them
        }
      }
      offset += fv;
    }
  }
  if (m.triangles.empty()) throw InputError(fmt::format("{}: the OBJ file has no faces", path));
  // A mesh of nothing but lines and points has no surface to grow on, to climb or to render.
  const auto has_area = [&](const glm::uvec3& t) {
    const glm::dvec3 a(m.vertices[t.x]), b(m.vertices[t.y]), c(m.vertices[t.z]);
    return glm::length(glm::cross(b - a, c - a)) > 0.0;
  };
  if (std::none_of(m.triangles.begin(), m.triangles.end(), has_area))
    throw InputError(
        fmt::format("{}: every face has zero area (its corners coincide or lie on one line); expected "
                    "at least one face with an area",
                    path));
  if (!every_face_uv) {
    m.uvs.clear();
    m.uv_triangles.clear();
  }
  return m;
}

TriangleMesh load_scene_obj(const std::string& path) {
  TriangleMesh m = load_obj(path);
  const std::size_t before = m.triangles.size();
  geom::fill_small_holes(m);  // leaves an open or badly holed mesh as it is: it has no inside
  if (m.has_uvs() && m.triangles.size() > before) {
    // The patches have no place in the texture: all their corners get one coordinate outside the unit
    // square, a triangle of no area in UV, which no texture lookup finds.
    const auto none = static_cast<unsigned>(m.uvs.size());
    m.uvs.emplace_back(-1.0f, -1.0f);
    m.uv_triangles.resize(m.triangles.size(), glm::uvec3(none));
  }
  return m;
}

void fit_scene(Scene& s, float size) {
  Aabb b;
  for (const auto& m : s.meshes) b.extend(m.bounds());
  if (b.empty()) return;
  const glm::vec3 ext = b.size();
  const float k = size / std::max({ext.x, ext.y, ext.z, 1e-12f});
  const glm::vec3 shift(-b.center().x, -b.min.y, -b.center().z);
  auto f = [&](const glm::vec3& p) { return (p + shift) * k; };
  for (auto& m : s.meshes)
    for (auto& v : m.vertices) v = f(v);
  for (auto& sd : s.seeds) sd.position = f(sd.position);
  auto fit_shape = [&](Shape& sh) {
    sh.min = f(sh.min);
    sh.max = f(sh.max);
    sh.center = f(sh.center);
    sh.radii *= k;
    for (auto& v : sh.mesh.vertices) v = f(v);
  };
  if (s.envelope) fit_shape(*s.envelope);
  for (auto& z : s.zones) fit_shape(z.shape);
  if (s.light.kind == Light::Kind::Point) s.light.position = f(s.light.position);
  s.camera.position = f(s.camera.position);
  s.camera.look_at = f(s.camera.look_at);
}

namespace {

// Frames a scene's bounds from the front, a little above.
Camera frame_camera(const Aabb& b) {
  const glm::vec3 c = b.center();
  const float r = 0.5f * glm::length(b.size());
  return {c + glm::vec3(0.35f * r, 0.45f * r, 2.6f * r), c, 45.0f};
}

// The default seed of a mesh scene: the foot of the mesh's lit side, where a climber rooted beside it
// would meet it. That is the lowest vertex whose normal is within 60 degrees of horizontal and faces
// the light (then any such vertex; then the lowest of all), lowest index among ties, growing up along
// the surface (world up laid into its tangent plane). The lowest vertex of all usually lies on an
// underside facing the ground, where a plant pointed up grows into the solid; and a seed in the shadow
// behind the mesh is hidden from the default camera, which looks from the light's side.
Seed side_foot_seed(const TriangleMesh& m, const glm::vec3& light) {
  const std::vector<glm::vec3> normal = geom::vertex_normal_sums(m);
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  std::size_t lit = kNone, side = kNone, lowest = 0;
  auto lower = [&](std::size_t i, std::size_t than) { return than == kNone || m.vertices[i].y < m.vertices[than].y; };
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    if (lower(i, lowest)) lowest = i;
    const float len = glm::length(normal[i]);
    if (!(len > 0.0f) || std::abs(normal[i].y) > 0.5f * len) continue;
    if (lower(i, side)) side = i;
    if (glm::dot(normal[i], light) > 0.0f && lower(i, lit)) lit = i;
  }
  const std::size_t at = lit != kNone ? lit : side;
  if (at == kNone) return {m.vertices[lowest], {0, 1, 0}, 0};
  const glm::vec3 n = glm::normalize(normal[at]);
  const glm::vec3 up = glm::vec3(0, 1, 0) - n.y * n;
  return {m.vertices[at], glm::length(up) > 1e-6f ? glm::normalize(up) : glm::vec3(0, 1, 0), 0};
}

Scene mesh_scene(const std::string& path, const Params& p) {
  Scene s;
  s.name = fs::path(path).stem().string();
  s.meshes.push_back(load_scene_obj(path));
  const auto size = static_cast<float>(p.real("size"));
  if (size > 0.0f) fit_scene(s, size);
  const Aabb b = s.meshes[0].bounds();
  s.seeds.push_back(side_foot_seed(s.meshes[0], s.light.towards(b.center())));
  if (p.boolean("ground")) {
    const float half = 0.75f * std::max(b.size().x, b.size().z) + 0.5f;
    auto g = geom::make_box("ground", {b.center().x - half, b.min.y - 0.1f, b.center().z - half},
                            {b.center().x + half, b.min.y, b.center().z + half});
    g.climbable = false;
    s.meshes.push_back(std::move(g));
  }
  Shape env;
  env.kind = Shape::Kind::Box;
  const glm::vec3 pad = 0.1f * b.size();
  env.min = b.min - pad;
  env.max = b.max + pad;
  s.envelope = env;
  s.camera = frame_camera(b);
  return s;
}

// The scene files whose bases are being read, outermost first, each as given and as its canonical path:
// a base that is one of them is a cycle. Bases nest at most kMaxBaseDepth files deep.
struct BaseLink {
  std::string shown, canonical;
};
using BaseChain = std::vector<BaseLink>;
constexpr std::size_t kMaxBaseDepth = 16;

// An error in the chain of bases as a whole: each file of the chain would otherwise prefix it again.
class BaseChainError : public InputError {
 public:
  using InputError::InputError;
};

Scene load_scene_in(const std::string& spec, const std::vector<std::string>& assignments, const BaseChain& chain);

// A small reader that remembers the JSON path, so every error says where it is.
class JsonScene : public JsonPathReader {
 public:
  JsonScene(std::string file, fs::path dir, const BaseChain& chain)
      : JsonPathReader(std::move(file)), dir_(std::move(dir)), chain_(chain) {}
  const json& need(const json& j, const std::string& path, const char* key) const {
    if (!j.contains(key)) fail(path, fmt::format("missing required key '{}'", key));
    return j.at(key);
  }
  float number(const json& j, const std::string& path, float lo = -1e30f, float hi = 1e30f) const {
    if (!j.is_number()) fail(path, fmt::format("expected a number, got {}", j.dump()));
    const double v = j.get<double>();
    if (!std::isfinite(v) || v < lo || v > hi)
      fail(path, fmt::format("expected a number in [{}, {}], got {}", lo, hi, v));
    return static_cast<float>(v);
  }
  glm::vec3 vec3(const json& j, const std::string& path) const {
    if (!j.is_array() || j.size() != 3) fail(path, fmt::format("expected an array of three numbers, got {}", j.dump()));
    const float m = kMaxCoordinate;
    return {number(j[0], path + "/0", -m, m), number(j[1], path + "/1", -m, m), number(j[2], path + "/2", -m, m)};
  }
  std::string string(const json& j, const std::string& path) const {
    if (!j.is_string()) fail(path, fmt::format("expected a string, got {}", j.dump()));
    return j.get<std::string>();
  }
  // A path in the scene file (at JSON path `where`), relative to the file, or a bundled mesh's name.
  std::string resolve(const std::string& rel, const std::string& where) const {
    if (is_mesh_name(rel)) {
      try {
        return mesh_path(rel);
      } catch (const InputError& e) {
        fail(where, e.what());
      }
    }
    const fs::path p(rel);
    return (p.is_absolute() ? p : dir_ / p).string();
  }

  TriangleMesh mesh(const json& j, const std::string& path) const {
    only_keys(j, path, {"name", "obj", "box", "sphere", "cylinder", "transform", "climbable", "visible"});
    TriangleMesh m;
    const std::string name = j.contains("name") ? string(j["name"], path + "/name") : "mesh";
    if (const std::string bad = name_problem(name); !bad.empty()) fail(path + "/name", bad);
    int kinds = 0;
    if (j.contains("obj")) {
      ++kinds;
      const std::string f = resolve(string(j["obj"], path + "/obj"), path + "/obj");
      try {
        m = load_scene_obj(f);
      } catch (const InputError& e) {
        fail(path + "/obj", e.what());
      }
    }
    if (j.contains("box")) {
      ++kinds;
      const auto& b = j["box"];
      only_keys(b, path + "/box", {"min", "max"});
      const glm::vec3 lo = vec3(need(b, path + "/box", "min"), path + "/box/min");
      const glm::vec3 hi = vec3(need(b, path + "/box", "max"), path + "/box/max");
      if (glm::any(glm::lessThanEqual(hi, lo))) fail(path + "/box", "expected max > min on every axis");
      m = geom::make_box(name, lo, hi);
    }
    if (j.contains("sphere")) {
      ++kinds;
      const auto& s = j["sphere"];
      only_keys(s, path + "/sphere", {"center", "radius", "subdivisions"});
      const int sub = s.contains("subdivisions")
                          ? static_cast<int>(number(s["subdivisions"], path + "/sphere/subdivisions", 0, 7))
                          : 4;
      m = geom::make_icosphere(name, vec3(need(s, path + "/sphere", "center"), path + "/sphere/center"),
                               number(need(s, path + "/sphere", "radius"), path + "/sphere/radius", 1e-6f), sub);
    }
    if (j.contains("cylinder")) {
      ++kinds;
      const auto& c = j["cylinder"];
      const std::string cp = path + "/cylinder";
      only_keys(c, cp, {"base", "top", "radius", "top_radius", "sides"});
      const float r = number(need(c, cp, "radius"), cp + "/radius", 1e-6f);
      const float rt = c.contains("top_radius") ? number(c["top_radius"], cp + "/top_radius", 1e-6f) : r;
      const int sides = c.contains("sides") ? static_cast<int>(number(c["sides"], cp + "/sides", 3, 1024)) : 32;
      const glm::vec3 base = vec3(need(c, cp, "base"), cp + "/base"), top = vec3(need(c, cp, "top"), cp + "/top");
      if (glm::length(top - base) <= 0.0f) fail(cp, "expected top != base");
      m = geom::make_cylinder(name, base, top, r, rt, sides);
    }
    if (kinds != 1) fail(path, "expected exactly one of 'obj', 'box', 'sphere', 'cylinder'");
    m.name = name;
    if (j.contains("transform")) {
      const auto& t = j["transform"];
      const std::string tp = path + "/transform";
      only_keys(t, tp, {"translate", "rotate_deg", "scale"});
      glm::vec3 scale(1.0f);
      if (t.contains("scale")) {
        if (t["scale"].is_number())
          scale = glm::vec3(number(t["scale"], tp + "/scale", 1e-9f));
        else
          scale = vec3(t["scale"], tp + "/scale");
        if (glm::any(glm::equal(scale, glm::vec3(0.0f)))) fail(tp + "/scale", "expected non-zero scale factors");
      }
      m.transform(geom::trs(t.contains("translate") ? vec3(t["translate"], tp + "/translate") : glm::vec3(0.0f),
                            t.contains("rotate_deg") ? vec3(t["rotate_deg"], tp + "/rotate_deg") : glm::vec3(0.0f),
                            scale));
    }
    if (j.contains("climbable")) {
      if (!j["climbable"].is_boolean()) fail(path + "/climbable", "expected true or false");
      m.climbable = j["climbable"].get<bool>();
    }
    if (j.contains("visible")) {
      if (!j["visible"].is_boolean()) fail(path + "/visible", "expected true or false");
      m.visible = j["visible"].get<bool>();
    }
    return m;
  }

  Shape shape(const json& j, const std::string& path) const {
    Shape s;
    const std::string type = string(need(j, path, "type"), path + "/type");
    if (type == "box") {
      only_keys(j, path, {"type", "min", "max"});
      s.kind = Shape::Kind::Box;
      s.min = vec3(need(j, path, "min"), path + "/min");
      s.max = vec3(need(j, path, "max"), path + "/max");
      if (glm::any(glm::lessThanEqual(s.max, s.min))) fail(path, "expected max > min on every axis");
    } else if (type == "sphere") {
      only_keys(j, path, {"type", "center", "radius"});
      s.kind = Shape::Kind::Sphere;
      s.center = vec3(need(j, path, "center"), path + "/center");
      const auto& r = need(j, path, "radius");
      s.radii = r.is_array() ? vec3(r, path + "/radius") : glm::vec3(number(r, path + "/radius", 1e-6f));
      if (glm::any(glm::lessThanEqual(s.radii, glm::vec3(0.0f)))) fail(path + "/radius", "expected positive radii");
    } else if (type == "mesh") {
      only_keys(j, path, {"type", "obj"});
      s.kind = Shape::Kind::Mesh;
      try {
        s.mesh = load_scene_obj(resolve(string(need(j, path, "obj"), path + "/obj"), path + "/obj"));
      } catch (const InputError& e) {
        fail(path + "/obj", e.what());
      }
      if (!s.mesh.is_closed()) fail(path + "/obj", "a mesh shape must be a closed mesh");
    } else {
      fail(path + "/type", fmt::format("unknown shape type '{}'; expected box, sphere or mesh", type));
    }
    return s;
  }

  // Long because it reads each key of a scene file in turn, one short block per key, in the file's order.
  Scene scene(const json& j) const {
    only_keys(
        j, "",
        {"schema_version", "name", "base", "base_params", "meshes", "seeds", "light", "envelope", "zones", "camera"});
    const auto& ver = need(j, "", "schema_version");
    if (!ver.is_number_integer() || ver.get<int>() != 1)
      fail("/schema_version", fmt::format("expected 1 (the only scene schema so far), got {}", ver.dump()));
    Scene s;
    if (j.contains("base")) {
      std::vector<std::string> params;
      if (j.contains("base_params")) {
        const auto& bp = j["base_params"];
        if (!bp.is_object()) fail("/base_params", "expected an object of scene parameters");
        for (const auto& [k, v] : bp.items())
          params.push_back(k + "=" + (v.is_string() ? v.get<std::string>() : v.dump()));
      }
      std::string base = string(j["base"], "/base");
      if (base.rfind("mesh:", 0) == 0 && !is_mesh_name(base.substr(5)))
        base = "mesh:" + resolve(base.substr(5), "/base");
      else if (base.ends_with(".json"))
        base = resolve(base, "/base");
      try {
        s = load_scene_in(base, params, chain_);
      } catch (const BaseChainError&) {
        throw;
      } catch (const InputError& e) {
        fail("/base", e.what());
      }
    }
    s.name = j.contains("name") ? string(j["name"], "/name") : fs::path(file()).stem().string();
    if (const std::string bad = name_problem(s.name); !bad.empty()) fail("/name", bad);
    if (j.contains("meshes")) {
      const auto& ms = j["meshes"];
      if (!ms.is_array()) fail("/meshes", "expected an array of meshes");
      for (std::size_t i = 0; i < ms.size(); ++i) s.meshes.push_back(mesh(ms[i], fmt::format("/meshes/{}", i)));
    }
    if (s.meshes.empty()) fail("/meshes", "a scene needs at least one mesh (or a 'base')");
    if (j.contains("seeds")) {
      const auto& ss = j["seeds"];
      if (!ss.is_array()) fail("/seeds", "expected an array of seeds");
      s.seeds.clear();
      for (std::size_t i = 0; i < ss.size(); ++i) {
        const std::string p = fmt::format("/seeds/{}", i);
        only_keys(ss[i], p, {"position", "direction", "start_step"});
        Seed sd;
        sd.position = vec3(need(ss[i], p, "position"), p + "/position");
        if (ss[i].contains("direction")) {
          sd.direction = vec3(ss[i]["direction"], p + "/direction");
          if (glm::length(sd.direction) <= 0.0f) fail(p + "/direction", "expected a non-zero direction");
          sd.direction = glm::normalize(sd.direction);
        }
        if (ss[i].contains("start_step"))
          sd.start_step = static_cast<int>(number(ss[i]["start_step"], p + "/start_step", 0, 1e9f));
        s.seeds.push_back(sd);
      }
    }
    if (s.seeds.empty()) fail("/seeds", "a scene needs at least one seed (or a 'base' that has seeds)");
    if (j.contains("light")) {
      const auto& l = j["light"];
      const std::string type = string(need(l, "/light", "type"), "/light/type");
      if (type == "sun") {
        only_keys(l, "/light", {"type", "direction"});
        s.light.kind = Light::Kind::Sun;
        s.light.direction = vec3(need(l, "/light", "direction"), "/light/direction");
        if (glm::length(s.light.direction) <= 0.0f) fail("/light/direction", "expected a non-zero direction");
      } else if (type == "point") {
        only_keys(l, "/light", {"type", "position"});
        s.light.kind = Light::Kind::Point;
        s.light.position = vec3(need(l, "/light", "position"), "/light/position");
      } else {
        fail("/light/type", fmt::format("unknown light type '{}'; expected sun or point", type));
      }
    }
    if (j.contains("envelope")) s.envelope = shape(j["envelope"], "/envelope");
    if (j.contains("zones")) {
      const auto& zs = j["zones"];
      if (!zs.is_array()) fail("/zones", "expected an array of zones");
      for (std::size_t i = 0; i < zs.size(); ++i) {
        const std::string p = fmt::format("/zones/{}", i);
        only_keys(zs[i], p, {"kind", "shape", "strength"});
        Zone z;
        const std::string kind = string(need(zs[i], p, "kind"), p + "/kind");
        if (kind == "attract")
          z.kind = Zone::Kind::Attract;
        else if (kind == "repel")
          z.kind = Zone::Kind::Repel;
        else if (kind == "include")
          z.kind = Zone::Kind::Include;
        else if (kind == "exclude")
          z.kind = Zone::Kind::Exclude;
        else
          fail(p + "/kind", fmt::format("unknown zone kind '{}'; expected attract, repel, include or exclude", kind));
        z.shape = shape(need(zs[i], p, "shape"), p + "/shape");
        if (zs[i].contains("strength")) z.strength = number(zs[i]["strength"], p + "/strength", 0.0f, 1e6f);
        s.zones.push_back(std::move(z));
      }
    }
    if (j.contains("camera")) {
      const auto& c = j["camera"];
      only_keys(c, "/camera", {"position", "look_at", "fov_deg"});
      s.camera.position = vec3(need(c, "/camera", "position"), "/camera/position");
      s.camera.look_at = vec3(need(c, "/camera", "look_at"), "/camera/look_at");
      if (c.contains("fov_deg")) s.camera.fov_deg = number(c["fov_deg"], "/camera/fov_deg", 1.0f, 170.0f);
    } else if (!j.contains("base")) {
      s.camera = frame_camera(s.bounds());
    }
    return s;
  }

 private:
  fs::path dir_;
  const BaseChain& chain_;
};

// `chain`: the files whose bases led here (empty for a scene named on the command line).
Scene json_scene(const std::string& path, const BaseChain& chain) {
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(path, ec);
  BaseChain longer = chain;
  longer.push_back({path, ec ? path : canonical.string()});
  auto names = [&] {
    std::vector<std::string> shown;
    for (const auto& l : longer) shown.push_back(l.shown);
    return fmt::format("{}", fmt::join(shown, " -> "));
  };
  for (const auto& l : chain)
    if (l.canonical == longer.back().canonical)
      throw BaseChainError(fmt::format("{}: at /base: the scene bases form a cycle: {}", chain.back().shown, names()));
  if (longer.size() > kMaxBaseDepth)
    throw BaseChainError(fmt::format("{}: at /base: scene bases nest more than {} files deep: {}", chain.back().shown,
                                     kMaxBaseDepth, names()));
  const json j = parse_json_file_text(path, read_text_file(path));
  return JsonScene(path, fs::path(path).parent_path(), longer).scene(j);
}

Scene load_scene_in(const std::string& spec, const std::vector<std::string>& assignments, const BaseChain& chain) {
  Scene s;
  if (spec.rfind("mesh:", 0) == 0) {
    const std::string path = mesh_path(spec.substr(5));
    Params p(fmt::format("scene '{}'", spec), mesh_scene_params());
    for (const auto& a : assignments) p.set_assignment(a);
    s = mesh_scene(path, p);
  } else if (spec.size() > 5 && spec.substr(spec.size() - 5) == ".json") {
    if (!assignments.empty())
      throw InputError(
          fmt::format("scene '{}': scene parameters go in the file's 'base_params', not on the command line", spec));
    s = json_scene(spec, chain);
  } else {
    const auto& list = standard_scenes();
    const auto it = std::find_if(list.begin(), list.end(), [&](const StandardScene& st) { return st.name == spec; });
    if (it == list.end()) {
      std::vector<std::string> names;
      for (const auto& st : list) names.push_back(st.name);
      const std::string near = closest_match(spec, names);
      throw InputError(fmt::format("unknown scene '{}'{}; expected one of {}, a scene file *.json, or mesh:PATH.obj",
                                   spec, near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near),
                                   fmt::join(names, ", ")));
    }
    Params p(fmt::format("scene '{}'", spec), it->params);
    for (const auto& a : assignments) p.set_assignment(a);
    s = it->build(p);
  }
  if (const std::string far = s.out_of_bounds(); !far.empty())
    throw InputError(
        fmt::format("scene '{}': {} lies beyond {:g} m of the origin; expected coordinates within "
                    "[-{:g}, {:g}] (a mesh in other units can be scaled by a scene file's 'transform')",
                    spec, far, kMaxCoordinate, kMaxCoordinate, kMaxCoordinate));
  s.source = spec;
  return s;
}

}  // namespace

Scene load_scene(const std::string& spec, const std::vector<std::string>& assignments) {
  return load_scene_in(spec, assignments, {});
}

}  // namespace growbench
