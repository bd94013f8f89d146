// Algorithms written in Python: a growbench plugin table (plugin.h, this version of its ABI) made from a Python class,
// with the host's queries offered to it as batched calls on numpy arrays. The loader dlopens this module
// when a plugin's path ends in .py (algorithms/plugins/loader.cpp) and asks growbench_python_plugin() for
// the script's table. The interpreter is Debian's CPython, embedded once per process and never finalized;
// Python runs only on the thread that drives the trial (the host's parallel loops are for native code).
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/embed.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "growbench/plugin.hpp"

namespace py = pybind11;
namespace sdk = growbench::sdk;

namespace {

using F32 = py::array_t<float, py::array::c_style | py::array::forcecast>;
using U64 = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>;
using U32 = py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>;

// ------------------------------------------------------------------ the host, as Python sees it

// (N, 3) float32 from anything numpy can convert; N = 0 for an empty input.
std::pair<F32, std::size_t> points_of(const py::handle& a, const char* what) {
  F32 p = F32::ensure(a);
  if (!p || p.ndim() != 2 || p.shape(1) != 3)
    throw py::value_error(std::string(what) + ": expected an (N, 3) array of points");
  return {p, static_cast<std::size_t>(p.shape(0))};
}
const growbench_vec3* vecs(const F32& p) {
  return reinterpret_cast<const growbench_vec3*>(p.data());
}
F32 new_points(std::size_t n) {
  return F32({static_cast<py::ssize_t>(n), py::ssize_t{3}});
}
py::array_t<bool> new_flags(const std::vector<std::uint8_t>& v) {
  py::array_t<bool> out(static_cast<py::ssize_t>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) out.mutable_data()[i] = v[i] != 0;
  return out;
}

class Host {
 public:
  Host(const growbench_host* h, const growbench_scene* scene) : h_(h), scene_(scene) {}

  [[nodiscard]] unsigned threads() const { return h_->threads; }
  [[nodiscard]] bool cancelled() const { return h_->cancelled(h_->context) != 0; }
  void log(const std::string& line) const { h_->log(h_->context, GROWBENCH_LOG_INFO, line.c_str()); }
  void warn(const std::string& line) const { h_->log(h_->context, GROWBENCH_LOG_WARNING, line.c_str()); }

  // Uniform in [0, 1) for each counter: the host's counter-based generator, as the C++ SDK's uniform().
  [[nodiscard]] py::array_t<double> uniform(std::uint64_t stream, const py::handle& counters) const {
    const U64 c = U64::ensure(counters);
    if (!c) throw py::value_error("uniform: expected an array of counters");
    py::array_t<double> out(c.size());
    for (py::ssize_t i = 0; i < c.size(); ++i)
      out.mutable_data()[i] = static_cast<double>(h_->random_bits(h_->context, stream, c.data()[i]) >> 11) * 0x1.0p-53;
    return out;
  }

  // (point (N, 3), normal (N, 3), distance (N,), found (N,) bool), and with `triangles` also (mesh (N,),
  // triangle (N,)), what surface_frames() takes.
  [[nodiscard]] py::tuple closest_points(const py::handle& p, float max_distance, bool climbable_only,
                                         bool triangles) const {
    const auto [pts, n] = points_of(p, "closest_points");
    std::vector<growbench_closest_hit> hits(n);
    h_->closest_points(h_->context, vecs(pts), n, max_distance, climbable_only ? 1 : 0, hits.data());
    F32 point = new_points(n), normal = new_points(n), distance(static_cast<py::ssize_t>(n));
    std::vector<std::uint8_t> found(n);
    for (std::size_t i = 0; i < n; ++i) {
      std::memcpy(point.mutable_data() + 3 * i, &hits[i].point, sizeof(growbench_vec3));
      std::memcpy(normal.mutable_data() + 3 * i, &hits[i].normal, sizeof(growbench_vec3));
      distance.mutable_data()[i] = hits[i].distance;
      found[i] = hits[i].found != 0;
    }
    if (!triangles) return py::make_tuple(point, normal, distance, new_flags(found));
    U32 mesh(static_cast<py::ssize_t>(n)), tri(static_cast<py::ssize_t>(n));
    for (std::size_t i = 0; i < n; ++i) {
      mesh.mutable_data()[i] = hits[i].mesh;
      tri.mutable_data()[i] = hits[i].triangle;
    }
    return py::make_tuple(point, normal, distance, new_flags(found), mesh, tri);
  }

  [[nodiscard]] std::vector<growbench_ray> rays_of(const py::handle& o, const py::handle& d, float tmin,
                                                   float tmax) const {
    const auto [origins, n] = points_of(o, "rays: origins");
    const auto [dirs, m] = points_of(d, "rays: directions");
    if (n != m) throw py::value_error("rays: origins and directions differ in length");
    std::vector<growbench_ray> r(n);
    for (std::size_t i = 0; i < n; ++i) r[i] = {vecs(origins)[i], vecs(dirs)[i], tmin, tmax};
    return r;
  }
  // (hit (N,) bool, t (N,), point (N, 3), normal (N, 3)).
  [[nodiscard]] py::tuple rays(const py::handle& o, const py::handle& d, float tmin, float tmax) const {
    const std::vector<growbench_ray> r = rays_of(o, d, tmin, tmax);
    std::vector<growbench_ray_hit> hits(r.size());
    h_->rays(h_->context, r.data(), r.size(), hits.data());
    F32 t(static_cast<py::ssize_t>(r.size())), point = new_points(r.size()), normal = new_points(r.size());
    std::vector<std::uint8_t> hit(r.size());
    for (std::size_t i = 0; i < r.size(); ++i) {
      hit[i] = hits[i].hit != 0;
      t.mutable_data()[i] = hits[i].t;
      std::memcpy(point.mutable_data() + 3 * i, &hits[i].point, sizeof(growbench_vec3));
      std::memcpy(normal.mutable_data() + 3 * i, &hits[i].normal, sizeof(growbench_vec3));
    }
    return py::make_tuple(new_flags(hit), t, point, normal);
  }
  [[nodiscard]] py::array_t<bool> occluded(const py::handle& o, const py::handle& d, float tmin, float tmax) const {
    const std::vector<growbench_ray> r = rays_of(o, d, tmin, tmax);
    std::vector<std::uint8_t> out(r.size());
    h_->occluded(h_->context, r.data(), r.size(), out.data());
    return new_flags(out);
  }
  // (distance (N,), gradient (N, 3)); ValueError when the scene has no distance field.
  [[nodiscard]] py::tuple signed_distance(const py::handle& p) const {
    const auto [pts, n] = points_of(p, "signed_distance");
    F32 d(static_cast<py::ssize_t>(n)), g = new_points(n);
    if (h_->signed_distance(h_->context, vecs(pts), n, d.mutable_data(),
                            reinterpret_cast<growbench_vec3*>(g.mutable_data())) != GROWBENCH_OK)
      throw py::value_error("signed_distance: the scene has no distance field");
    return py::make_tuple(d, g);
  }
  [[nodiscard]] py::array_t<bool> inside(const py::handle& p) const {
    const auto [pts, n] = points_of(p, "inside");
    std::vector<std::uint8_t> out(n);
    h_->inside(h_->context, vecs(pts), n, out.data());
    return new_flags(out);
  }
  [[nodiscard]] py::array_t<bool> inside_shape(int shape, const py::handle& p) const {
    const auto [pts, n] = points_of(p, "inside_shape");
    std::vector<std::uint8_t> out(n);
    h_->inside_shape(h_->context, shape, vecs(pts), n, out.data());
    return new_flags(out);
  }
  // (uvs (K, 2), triangles (T, 3)) of scene mesh `mesh`, or None when it has no texture coordinates.
  [[nodiscard]] py::object mesh_uvs(std::uint32_t mesh) const {
    const float* uvs = nullptr;
    const std::uint32_t* tris = nullptr;
    std::uint64_t k = 0;
    if (h_->mesh_uvs(h_->context, mesh, &uvs, &k, &tris) == 0) return py::none();
    const auto t = static_cast<py::ssize_t>(scene_->meshes[mesh].triangle_count);
    F32 u({static_cast<py::ssize_t>(k), py::ssize_t{2}});
    std::memcpy(u.mutable_data(), uvs, k * 2 * sizeof(float));
    U32 tri({t, py::ssize_t{3}});
    std::memcpy(tri.mutable_data(), tris, static_cast<std::size_t>(t) * 3 * sizeof(std::uint32_t));
    return py::make_tuple(u, tri);
  }
  // (found (N,) bool, uv (N, 2), normal (N, 3), dp_du (N, 3), dp_dv (N, 3)) at points on scene triangles.
  [[nodiscard]] py::tuple surface_frames(const py::handle& p, const py::handle& meshes,
                                         const py::handle& triangles) const {
    const auto [pts, n] = points_of(p, "surface_frames");
    const U32 m = U32::ensure(meshes), t = U32::ensure(triangles);
    if (!m || !t || static_cast<std::size_t>(m.size()) != n || static_cast<std::size_t>(t.size()) != n)
      throw py::value_error("surface_frames: expected N points, N mesh indices and N triangle indices");
    std::vector<growbench_surface_point> at(n);
    for (std::size_t i = 0; i < n; ++i) at[i] = {vecs(pts)[i], m.data()[i], t.data()[i]};
    std::vector<growbench_surface_frame> f(n);
    h_->surface_frames(h_->context, at.data(), n, f.data());
    F32 uv({static_cast<py::ssize_t>(n), py::ssize_t{2}}), normal = new_points(n), du = new_points(n),
                                                           dv = new_points(n);
    std::vector<std::uint8_t> found(n);
    for (std::size_t i = 0; i < n; ++i) {
      found[i] = f[i].found != 0;
      uv.mutable_data()[2 * i] = f[i].u;
      uv.mutable_data()[2 * i + 1] = f[i].v;
      std::memcpy(normal.mutable_data() + 3 * i, &f[i].normal, sizeof(growbench_vec3));
      std::memcpy(du.mutable_data() + 3 * i, &f[i].dp_du, sizeof(growbench_vec3));
      std::memcpy(dv.mutable_data() + 3 * i, &f[i].dp_dv, sizeof(growbench_vec3));
    }
    return py::make_tuple(new_flags(found), uv, normal, du, dv);
  }
  [[nodiscard]] py::array_t<bool> light_visible(const py::handle& p, float bias) const {
    const auto [pts, n] = points_of(p, "light_visible");
    std::vector<std::uint8_t> out(n);
    h_->light_visible(h_->context, vecs(pts), n, bias, out.data());
    return new_flags(out);
  }
  // (position (N, 3), normal (N, 3)) of samples first .. first + n - 1.
  [[nodiscard]] py::tuple sample_surface(std::uint64_t seed, std::uint64_t first, std::size_t n) const {
    std::vector<growbench_surface_sample> s(n);
    h_->sample_surface(h_->context, seed, first, n, s.data());
    F32 position = new_points(n), normal = new_points(n);
    for (std::size_t i = 0; i < n; ++i) {
      std::memcpy(position.mutable_data() + 3 * i, &s[i].position, sizeof(growbench_vec3));
      std::memcpy(normal.mutable_data() + 3 * i, &s[i].normal, sizeof(growbench_vec3));
    }
    return py::make_tuple(position, normal);
  }

 private:
  const growbench_host* h_;
  const growbench_scene* scene_;  // lives as long as the instance
};

// A parameter row as the class's `params` list gives it: growbench.real("step", 0.01, min=..., ...).
py::dict row(const char* type, const std::string& name, py::object value, double min, double max,
             const std::string& unit, const std::string& doc) {
  py::dict d;
  d["type"] = type;
  d["name"] = name;
  d["default"] = std::move(value);
  d["min"] = min;
  d["max"] = max;
  d["unit"] = unit;
  d["doc"] = doc;
  return d;
}

}  // namespace

PYBIND11_EMBEDDED_MODULE(growbench, m) {
  m.doc() = "growbench's host, for algorithms written in Python (docs/plugins.md, 'Algorithms in Python')";
  // Raised by an algorithm for parameters or a scene it cannot work with: the trial is invalid_input.
  m.attr("InputError") =
      py::reinterpret_steal<py::object>(PyErr_NewException("growbench.InputError", PyExc_ValueError, nullptr));
  constexpr double inf = HUGE_VAL;
  m.def(
      "real",
      [](const std::string& n, double v, double lo, double hi, const std::string& unit, const std::string& doc) {
        return row("real", n, py::float_(v), lo, hi, unit, doc);
      },
      py::arg("name"), py::arg("default"), py::arg("min") = -inf, py::arg("max") = inf, py::arg("unit") = "",
      py::arg("doc") = "");
  m.def(
      "integer",
      [](const std::string& n, std::int64_t v, double lo, double hi, const std::string& unit, const std::string& doc) {
        return row("integer", n, py::int_(v), lo, hi, unit, doc);
      },
      py::arg("name"), py::arg("default"), py::arg("min") = -inf, py::arg("max") = inf, py::arg("unit") = "",
      py::arg("doc") = "");
  m.def(
      "boolean",
      [](const std::string& n, bool v, const std::string& doc) {
        return row("boolean", n, py::bool_(v), 0, 0, "", doc);
      },
      py::arg("name"), py::arg("default"), py::arg("doc") = "");
  m.def(
      "choice",
      [](const std::string& n, const std::string& v, const std::vector<std::string>& choices, const std::string& doc) {
        py::dict d = row("choice", n, py::str(v), 0, 0, "", doc);
        d["choices"] = choices;
        return d;
      },
      py::arg("name"), py::arg("default"), py::arg("choices"), py::arg("doc") = "");
  m.attr("ENVELOPE") = GROWBENCH_ENVELOPE;
  m.attr("KIND_SHAPE") = GROWBENCH_KIND_SHAPE;
  m.attr("PLANAR_DECAL") = GROWBENCH_PLANAR_DECAL;
  m.attr("LEAF") = static_cast<int>(GROWBENCH_ORGAN_LEAF);
  m.attr("YOUNG_LEAF") = static_cast<int>(GROWBENCH_ORGAN_YOUNG_LEAF);
  m.attr("FLOWER") = static_cast<int>(GROWBENCH_ORGAN_FLOWER);
  m.attr("BUD") = static_cast<int>(GROWBENCH_ORGAN_BUD);
  py::class_<Host>(m, "Host", "the host's queries, batched over numpy arrays of points (N, 3)")
      .def_property_readonly("threads", &Host::threads)
      .def("cancelled", &Host::cancelled)
      .def("log", &Host::log)
      .def("warn", &Host::warn)
      .def("uniform", &Host::uniform, py::arg("stream"), py::arg("counters"))
      .def("closest_points", &Host::closest_points, py::arg("points"), py::arg("max_distance") = HUGE_VALF,
           py::arg("climbable_only") = false, py::arg("triangles") = false)
      .def("mesh_uvs", &Host::mesh_uvs, py::arg("mesh"))
      .def("surface_frames", &Host::surface_frames, py::arg("points"), py::arg("meshes"), py::arg("triangles"))
      .def("rays", &Host::rays, py::arg("origins"), py::arg("directions"), py::arg("tmin") = 0.0f,
           py::arg("tmax") = HUGE_VALF)
      .def("occluded", &Host::occluded, py::arg("origins"), py::arg("directions"), py::arg("tmin") = 0.0f,
           py::arg("tmax") = HUGE_VALF)
      .def("signed_distance", &Host::signed_distance, py::arg("points"))
      .def("inside", &Host::inside, py::arg("points"))
      .def("inside_shape", &Host::inside_shape, py::arg("shape"), py::arg("points"))
      .def("light_visible", &Host::light_visible, py::arg("points"), py::arg("bias") = 1e-4f)
      .def("sample_surface", &Host::sample_surface, py::arg("seed"), py::arg("first"), py::arg("n"));
}

namespace {

// ------------------------------------------------------------------ one script's table

// What a plugin table made from a script owns: the class, and the SDK's Info, which the table's name,
// summary, version, parameter rows and test parameters point into (as a C++ plugin's do).
struct Script {
  py::object cls;
  std::optional<sdk::Info> info;
  growbench_plugin table{};
};

// The instance behind a growbench_instance: the Python object, and the plant it last handed over.
struct Instance {
  const growbench_host* host = nullptr;
  const Script* script = nullptr;
  py::object self;
  std::vector<growbench_node> nodes;
  std::vector<growbench_organ> organs;
  std::vector<std::string> shape_names;
  std::vector<const char*> shapes;
  std::vector<std::uint16_t> organ_shape;
  std::vector<growbench_vec3> organ_tint;
  std::vector<std::string> attribute_names;
  std::vector<std::vector<float>> attribute_values;
  std::vector<std::uint32_t> attribute_components;
  std::vector<std::int32_t> groups;
  std::string group_prefix;
  std::vector<std::vector<std::uint8_t>> decal_pixels;
  std::vector<growbench_decal> decals;
  bool stale = true;  // the Python plant changed since it was last taken (start, step and finish change it)
  std::vector<growbench_attribute> attributes;
  std::vector<std::string> stat_names;
  std::vector<growbench_stat> stats;
};

// growbench.InputError, looked up once the module exists (no lookup, which could throw, in a handler).
PyObject* g_input_error = nullptr;

std::string text_of(const py::handle& h, const char* fallback = "") {
  return h.is_none() ? fallback : py::str(h).cast<std::string>();
}

// Runs `f`, turning a Python exception into the status the ABI expects and its message for the host.
template <class F>
int32_t guarded(const growbench_host* host, F&& f) {
  try {
    return f();
  } catch (py::error_already_set& e) {
    const bool input = e.matches(g_input_error);
    const bool memory = e.matches(PyExc_MemoryError);
    std::string what = e.what();  // the exception and its traceback
    host->fail(host->context, what.c_str());
    return input ? GROWBENCH_INPUT_ERROR : memory ? GROWBENCH_OUT_OF_MEMORY : GROWBENCH_ERROR;
  } catch (const std::exception& e) {
    host->fail(host->context, e.what());
    return GROWBENCH_ERROR;
  }
}

Instance& self(growbench_instance* i) {
  return *reinterpret_cast<Instance*>(i);
}

py::object scene_object(const growbench_scene& s) {
  F32 positions = new_points(s.seed_count), directions = new_points(s.seed_count);
  for (std::uint32_t i = 0; i < s.seed_count; ++i) {
    std::memcpy(positions.mutable_data() + 3 * i, &s.seeds[i].position, sizeof(growbench_vec3));
    std::memcpy(directions.mutable_data() + 3 * i, &s.seeds[i].direction, sizeof(growbench_vec3));
  }
  auto v3 = [](const growbench_vec3& v) { return py::make_tuple(v.x, v.y, v.z); };
  py::dict d;
  d["name"] = s.name ? s.name : "";
  d["seed_positions"] = positions;
  d["seed_directions"] = directions;
  d["bounds_min"] = v3(s.bounds_min);
  d["bounds_max"] = v3(s.bounds_max);
  d["has_sdf"] = s.has_sdf != 0;
  d["voxel_size"] = s.voxel_size;
  d["has_envelope"] = s.has_envelope != 0;
  d["envelope_min"] = v3(s.envelope.min);
  d["envelope_max"] = v3(s.envelope.max);
  d["light_is_point"] = s.light.point != 0;
  d["light_direction"] = v3(s.light.direction);
  d["light_position"] = v3(s.light.position);
  d["zone_count"] = s.zone_count;
  const py::object ns = py::module_::import("types").attr("SimpleNamespace");
  py::list meshes;
  for (std::uint32_t k = 0; k < s.mesh_count; ++k) {
    const growbench_mesh& m = s.meshes[k];
    F32 v = new_points(m.vertex_count);
    std::memcpy(v.mutable_data(), m.vertices, m.vertex_count * sizeof(growbench_vec3));
    U32 t({static_cast<py::ssize_t>(m.triangle_count), py::ssize_t{3}});
    std::memcpy(t.mutable_data(), m.triangles, m.triangle_count * 3 * sizeof(std::uint32_t));
    meshes.append(ns(py::arg("name") = m.name ? m.name : "", py::arg("vertices") = v, py::arg("triangles") = t,
                     py::arg("climbable") = m.climbable != 0, py::arg("solid") = m.solid != 0));
  }
  d["meshes"] = meshes;
  return ns(**d);
}

py::dict params_object(const Script& sc, const growbench_value* values) {
  py::dict p;
  for (std::size_t k = 0; k < sc.table.param_count; ++k) {
    const growbench_param& r = sc.table.params[k];
    const growbench_value& v = values[k];
    switch (r.type) {
      case GROWBENCH_PARAM_INT:
        p[r.name] = v.integer;
        break;
      case GROWBENCH_PARAM_REAL:
        p[r.name] = v.real;
        break;
      case GROWBENCH_PARAM_BOOL:
        p[r.name] = v.boolean != 0;
        break;
      case GROWBENCH_PARAM_VEC3:
        p[r.name] = py::make_tuple(v.vec3[0], v.vec3[1], v.vec3[2]);
        break;
      default:
        p[r.name] = v.text ? v.text : "";
        break;
    }
  }
  return p;
}

// An optional (n,) or (n, k) array of the plant dict, as `T`, or empty when absent.
template <class T>
std::vector<T> column(const py::dict& d, const char* key, std::size_t n, std::size_t k = 1) {
  if (!d.contains(key) || d[key].is_none()) return {};
  auto a = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(d[key]);
  if (!a || static_cast<std::size_t>(a.size()) != n * k)
    throw py::value_error(std::string("plant['") + key + "']: expected " + std::to_string(n) +
                          (k > 1 ? " x " + std::to_string(k) : "") + " values");
  return std::vector<T>(a.data(), a.data() + a.size());
}

void take_nodes(Instance& s, const py::dict& d) {
  if (!d.contains("positions")) throw py::value_error("plant: expected the key 'positions', an (N, 3) array");
  const auto [pts, n] = points_of(d["positions"], "plant['positions']");
  const auto radius = column<float>(d, "radius", n);
  const auto parent = column<std::int64_t>(d, "parent", n);
  const auto order = column<std::int64_t>(d, "order", n), shoot = column<std::int64_t>(d, "shoot", n);
  const auto birth = column<std::int64_t>(d, "birth_step", n);
  if (parent.empty() && n > 0) throw py::value_error("plant: expected the key 'parent', N parent indices (-1: a root)");
  // Integers that do not fit their C members are refused, not wrapped into valid-looking ones.
  auto fits = [](const std::vector<std::int64_t>& v, std::int64_t lo, std::int64_t hi, const char* key) {
    for (std::size_t i = 0; i < v.size(); ++i)
      if (v[i] < lo || v[i] > hi)
        throw py::value_error(std::string("plant['") + key + "'][" + std::to_string(i) + "] is " +
                              std::to_string(v[i]) + ", outside [" + std::to_string(lo) + ", " + std::to_string(hi) +
                              "]");
  };
  fits(parent, -1, INT32_MAX, "parent");
  fits(order, 0, UINT32_MAX, "order");
  fits(shoot, 0, UINT32_MAX, "shoot");
  fits(birth, 0, UINT32_MAX, "birth_step");
  s.nodes.assign(n, growbench_node{});
  for (std::size_t i = 0; i < n; ++i) {
    growbench_node& g = s.nodes[i];
    g.position = vecs(pts)[i];
    g.radius = radius.empty() ? 0.002f : radius[i];
    g.parent = static_cast<int32_t>(parent[i]);
    g.order = order.empty() ? 0 : static_cast<uint32_t>(order[i]);
    g.shoot = shoot.empty() ? 0 : static_cast<uint32_t>(shoot[i]);
    g.birth_step = birth.empty() ? 0 : static_cast<uint32_t>(birth[i]);
  }
}

void take_organs(Instance& s, const py::dict& d) {
  s.organs.clear();
  s.organ_shape.clear();
  s.organ_tint.clear();
  s.shape_names.clear();
  if (!d.contains("organ_positions")) return;
  const auto [pts, m] = points_of(d["organ_positions"], "plant['organ_positions']");
  const auto turn = column<float>(d, "organ_orientations", m, 4), size = column<float>(d, "organ_sizes", m);
  const auto kind = column<std::int32_t>(d, "organ_kinds", m), node = column<std::int32_t>(d, "organ_nodes", m);
  const auto shape = column<std::int64_t>(d, "organ_shape", m);
  for (std::size_t i = 0; i < shape.size(); ++i)
    if (shape[i] < 0 || shape[i] > GROWBENCH_KIND_SHAPE)
      throw py::value_error("plant['organ_shape'][" + std::to_string(i) + "] is " + std::to_string(shape[i]) +
                            ": expected an index into organ_shapes, or growbench.KIND_SHAPE");
  s.organs.assign(m, growbench_organ{});
  for (std::size_t i = 0; i < m; ++i) {
    growbench_organ& o = s.organs[i];
    o.position = vecs(pts)[i];
    if (turn.empty()) o.orientation[0] = 1.0f;
    for (int c = 0; c < 4 && !turn.empty(); ++c) o.orientation[c] = turn[4 * i + c];
    o.size = size.empty() ? 0.03f : size[i];
    o.kind = kind.empty() ? GROWBENCH_ORGAN_LEAF : kind[i];
    o.node = node.empty() ? -1 : node[i];
  }
  s.organ_shape.assign(shape.begin(), shape.end());
  const auto tint = column<float>(d, "organ_tint", m, 3);
  s.organ_tint.assign(tint.size() / 3, growbench_vec3{});
  if (!tint.empty()) std::memcpy(s.organ_tint.data(), tint.data(), tint.size() * sizeof(float));
  s.shape_names =
      d.contains("organ_shapes") ? d["organ_shapes"].cast<std::vector<std::string>>() : std::vector<std::string>{};
}

void take_attributes(Instance& s, const py::dict& d) {
  s.attribute_names.clear();
  s.attribute_values.clear();
  s.attribute_components.clear();
  if (!d.contains("attributes")) return;
  for (const auto& [key, value] : d["attributes"].cast<py::dict>()) {
    auto a = F32::ensure(value);
    const std::size_t n = s.nodes.size();
    const std::size_t k = a && a.ndim() == 2 ? static_cast<std::size_t>(a.shape(1)) : 1;
    if (!a || static_cast<std::size_t>(a.size()) != n * k)
      throw py::value_error("plant['attributes']['" + text_of(key) + "']: expected N or (N, k) values");
    s.attribute_names.push_back(text_of(key));
    s.attribute_values.emplace_back(a.data(), a.data() + a.size());
    s.attribute_components.push_back(static_cast<std::uint32_t>(k));
  }
}

growbench_vec3 vec3_of(const py::dict& d, const char* key, growbench_vec3 fallback) {
  if (!d.contains(key)) return fallback;
  const auto v = d[key].cast<std::array<float, 3>>();
  return {v[0], v[1], v[2]};
}

// plant['groups'] (N ints, -1 for none) with plant['group_prefix'], and plant['decals']: a list of dicts with
// 'image' (H, W, 4) uint8, the top row first, and 'mesh' (an index, or growbench.PLANAR_DECAL with 'origin',
// 'u_axis' and 'v_axis').
void take_groups_and_decals(Instance& s, const py::dict& d) {
  s.groups = column<std::int32_t>(d, "groups", s.nodes.size());
  s.group_prefix = d.contains("group_prefix") ? text_of(d["group_prefix"]) : "";
  s.decals.clear();
  s.decal_pixels.clear();
  if (!d.contains("decals")) return;
  for (const auto& item : d["decals"].cast<py::list>()) {
    const auto k = std::to_string(s.decals.size());
    const auto e = item.cast<py::dict>();
    using U8 = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>;
    const U8 image = e.contains("image") ? U8::ensure(e["image"]) : U8();
    if (!image || image.ndim() != 3 || image.shape(2) != 4)
      throw py::value_error("plant['decals'][" + k + "]['image']: expected an (H, W, 4) array of uint8");
    growbench_decal g{};
    g.mesh = e.contains("mesh") ? e["mesh"].cast<std::int32_t>() : GROWBENCH_PLANAR_DECAL;
    g.origin = vec3_of(e, "origin", {0.0f, 0.0f, 0.0f});
    g.u_axis = vec3_of(e, "u_axis", {1.0f, 0.0f, 0.0f});
    g.v_axis = vec3_of(e, "v_axis", {0.0f, 1.0f, 0.0f});
    g.height = static_cast<std::uint32_t>(image.shape(0));
    g.width = static_cast<std::uint32_t>(image.shape(1));
    s.decal_pixels.emplace_back(image.data(), image.data() + image.size());
    s.decals.push_back(g);
  }
}

void fill_view(Instance& s, growbench_plant_view* out) {
  std::memset(out, 0, sizeof(*out));
  out->nodes = s.nodes.data();
  out->node_count = s.nodes.size();
  out->organs = s.organs.data();
  out->organ_count = s.organs.size();
  s.shapes.clear();
  for (const auto& n : s.shape_names) s.shapes.push_back(n.c_str());
  out->organ_shapes = s.shapes.data();
  out->organ_shape_count = static_cast<uint32_t>(s.shapes.size());
  out->organ_shape = s.organ_shape.empty() ? nullptr : s.organ_shape.data();
  out->organ_tint = s.organ_tint.empty() ? nullptr : s.organ_tint.data();
  s.attributes.clear();
  for (std::size_t k = 0; k < s.attribute_names.size(); ++k)
    s.attributes.push_back({s.attribute_names[k].c_str(), s.attribute_components[k], s.attribute_values[k].data()});
  out->node_attributes = s.attributes.data();
  out->node_attribute_count = static_cast<uint32_t>(s.attributes.size());
  out->node_groups = s.groups.empty() ? nullptr : s.groups.data();
  out->group_prefix = s.group_prefix.c_str();
  for (std::size_t k = 0; k < s.decals.size(); ++k) s.decals[k].rgba = s.decal_pixels[k].data();
  out->decals = s.decals.data();
  out->decal_count = static_cast<uint32_t>(s.decals.size());
}

// The table's functions for the script in slot N: create() is given only the host, so each script's table
// has its own create (and one slot of kSlots).
constexpr int kSlots = 8;
std::array<Script*, kSlots> g_scripts{};

template <int N>
growbench_instance* create(const growbench_host* host) {
  auto* inst = new (std::nothrow) Instance;
  if (!inst) return nullptr;
  inst->host = host;
  inst->script = g_scripts[N];
  const int32_t r = guarded(host, [&] {
    inst->self = inst->script->cls();
    return int32_t{GROWBENCH_OK};
  });
  if (r != GROWBENCH_OK) {
    delete inst;
    return nullptr;
  }
  return reinterpret_cast<growbench_instance*>(inst);
}

int32_t start(growbench_instance* i, const growbench_scene* scene, const growbench_value* values, uint64_t seed) {
  Instance& s = self(i);
  return guarded(s.host, [&] {
    s.stale = true;
    s.self.attr("start")(scene_object(*scene), Host(s.host, scene), params_object(*s.script, values), seed);
    return int32_t{GROWBENCH_OK};
  });
}

int32_t step(growbench_instance* i) {
  Instance& s = self(i);
  bool more = false;
  const int32_t r = guarded(s.host, [&] {
    s.stale = true;
    more = py::bool_(s.self.attr("step")());
    return int32_t{GROWBENCH_OK};
  });
  return r != GROWBENCH_OK ? -r : (more ? 1 : 0);
}

int32_t finish(growbench_instance* i) {
  Instance& s = self(i);
  return guarded(s.host, [&] {
    s.stale = true;
    if (py::hasattr(s.self, "finish")) s.self.attr("finish")();
    return int32_t{GROWBENCH_OK};
  });
}

// The Python plant, taken once per change: plant() and counts() after the same step share it.
void take_plant(Instance& s) {
  if (!s.stale) return;
  const py::dict d = s.self.attr("plant")();
  take_nodes(s, d);
  take_organs(s, d);
  take_attributes(s, d);
  take_groups_and_decals(s, d);
  s.stale = false;
}

int32_t plant(growbench_instance* i, growbench_plant_view* out) {
  Instance& s = self(i);
  return guarded(s.host, [&] {
    take_plant(s);
    fill_view(s, out);
    return int32_t{GROWBENCH_OK};
  });
}

// The counts the host reads after every step: the class's counts() when it has one (cheaper than building
// the plant dict), else the plant's, taken once per step.
void counts(growbench_instance* i, uint64_t* nodes, uint64_t* organs) {
  Instance& s = self(i);
  *nodes = *organs = 0;
  guarded(s.host, [&] {
    if (py::hasattr(s.self, "counts")) {
      const auto c = s.self.attr("counts")().cast<std::pair<std::uint64_t, std::uint64_t>>();
      *nodes = c.first;
      *organs = c.second;
    } else {
      take_plant(s);
      *nodes = s.nodes.size();
      *organs = s.organs.size();
    }
    return int32_t{GROWBENCH_OK};
  });
}

uint32_t stats(growbench_instance* i, const growbench_stat** out) {
  Instance& s = self(i);
  s.stat_names.clear();
  s.stats.clear();
  const int32_t r = guarded(s.host, [&] {
    if (!py::hasattr(s.self, "stats")) return int32_t{GROWBENCH_OK};
    for (const auto& [k, v] : s.self.attr("stats")().cast<py::dict>()) {
      s.stat_names.push_back(text_of(k));
      s.stats.push_back({nullptr, v.cast<double>()});
    }
    return int32_t{GROWBENCH_OK};
  });
  if (r != GROWBENCH_OK) s.stats.clear();
  for (std::size_t k = 0; k < s.stats.size(); ++k) s.stats[k].name = s.stat_names[k].c_str();
  *out = s.stats.data();
  return static_cast<uint32_t>(s.stats.size());
}

void destroy(growbench_instance* i) {
  delete reinterpret_cast<Instance*>(i);
}

template <int... N>
constexpr std::array<growbench_instance* (*)(const growbench_host*), kSlots> creators(
    std::integer_sequence<int, N...>) {
  return {&create<N>...};
}

// The parameter type a row's 'type' names.
growbench_param_type param_type(const std::string& type) {
  static const std::array<std::pair<const char*, growbench_param_type>, 6> kTypes = {
      {{"integer", GROWBENCH_PARAM_INT},
       {"real", GROWBENCH_PARAM_REAL},
       {"boolean", GROWBENCH_PARAM_BOOL},
       {"text", GROWBENCH_PARAM_STRING},
       {"vector3", GROWBENCH_PARAM_VEC3},
       {"choice", GROWBENCH_PARAM_CHOICE}}};
  for (const auto& [name, t] : kTypes)
    if (type == name) return t;
  throw py::value_error("params: unknown type '" + type + "'; use growbench.real(), integer(), ...");
}

// One row of the table from the class's `params` entry (a dict as growbench.real() makes), as the SDK's
// Param. Its keys are read in the order type, name, default, min, max, unit, doc, choices: a row with
// several faults is refused for the first of them. A vector3 row (growbench has no helper for one)
// defaults to the origin, whatever its 'default'.
sdk::Param param_of(const py::dict& d) {
  const growbench_param_type type = param_type(text_of(d["type"]));
  const std::string name = text_of(d["name"]);
  const py::object v = d["default"];
  std::optional<sdk::Param> p;
  if (type == GROWBENCH_PARAM_INT) p = sdk::integer(name, v.cast<std::int64_t>());
  if (type == GROWBENCH_PARAM_REAL) p = sdk::real(name, v.cast<double>());
  if (type == GROWBENCH_PARAM_BOOL) p = sdk::boolean(name, v.cast<bool>());
  if (type == GROWBENCH_PARAM_VEC3) p = sdk::vector3(name, 0.0, 0.0, 0.0);
  const std::string text = type == GROWBENCH_PARAM_STRING || type == GROWBENCH_PARAM_CHOICE ? text_of(v) : "";
  if (type == GROWBENCH_PARAM_STRING) p = sdk::text(name, text);
  const double min = d.contains("min") ? d["min"].cast<double>() : -HUGE_VAL;
  const double max = d.contains("max") ? d["max"].cast<double>() : HUGE_VAL;
  std::string unit = d.contains("unit") ? text_of(d["unit"]) : "";
  std::string doc = d.contains("doc") ? text_of(d["doc"]) : "";
  if (type == GROWBENCH_PARAM_CHOICE) {
    std::vector<std::string> choices;
    for (const auto& x : d["choices"]) choices.push_back(text_of(x));
    p = sdk::choice(name, text, std::move(choices));
  }
  return std::move(*p).range(min, max).unit(std::move(unit)).doc(std::move(doc));
}

// The script's class: the module's PLUGIN.
py::object load_class(const std::string& path, int slot) {
  py::module_ sys = py::module_::import("sys");
  const std::string dir = path.substr(0, path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/'));
  if (!dir.empty()) sys.attr("path").attr("insert")(0, dir);
  py::module_ util = py::module_::import("importlib.util");
  // In sys.modules under its own name, as an imported module is (dataclasses and pickle look it up there).
  const std::string name = "growbench_plugin_" + std::to_string(slot);
  const py::object spec = util.attr("spec_from_file_location")(name, path);
  if (spec.is_none()) throw py::value_error(path + ": not a Python file");
  const py::object mod = util.attr("module_from_spec")(spec);
  sys.attr("modules")[py::str(name)] = mod;
  spec.attr("loader").attr("exec_module")(mod);
  if (!py::hasattr(mod, "PLUGIN"))
    throw py::value_error(path + ": no PLUGIN; end the file with PLUGIN = YourAlgorithmClass (docs/plugins.md)");
  return mod.attr("PLUGIN");
}

void fill_table(Script& sc, int slot) {
  const py::object& c = sc.cls;
  for (const char* key : {"name", "start", "step", "plant"})
    if (!py::hasattr(c, key))
      throw py::value_error(std::string("PLUGIN has no '") + key + "'; see docs/plugins.md, 'Algorithms in Python'");
  std::vector<sdk::Param> params;
  if (py::hasattr(c, "params"))
    for (const auto& row : c.attr("params")) params.push_back(param_of(row.cast<py::dict>()));
  std::vector<std::string> test_params;
  if (py::hasattr(c, "test_params"))
    for (const auto& a : c.attr("test_params")) test_params.push_back(text_of(a));
  std::string name = text_of(c.attr("name"));
  std::string summary = py::hasattr(c, "summary") ? text_of(c.attr("summary")) : "an algorithm written in Python";
  std::string version = py::hasattr(c, "version") ? text_of(c.attr("version")) : "";
  growbench_plugin& t = sc.table;
  t.abi_version = GROWBENCH_PLUGIN_ABI_VERSION;
  t.struct_size = sizeof(growbench_plugin);
  sc.info.emplace(std::move(name), std::move(summary), std::move(version), std::move(params), std::move(test_params))
      .fill(t);
  static constexpr auto kCreators = creators(std::make_integer_sequence<int, kSlots>{});
  t.create = kCreators[static_cast<std::size_t>(slot)];
  t.start = &start;
  t.step = &step;
  t.finish = &finish;
  t.plant = &plant;
  t.counts = &counts;
  t.stats = &stats;
  t.destroy = &destroy;
}

}  // namespace

namespace {

// Python without signal handlers of its own, and with string hashing fixed: each trial is a fresh process,
// and a random hash seed would let a script that walks a set of strings grow another plant in each.
void start_interpreter() {
  PyConfig config;
  PyConfig_InitPythonConfig(&config);
  config.install_signal_handlers = 0;
  config.use_hash_seed = 1;
  config.hash_seed = 0;
  py::initialize_interpreter(&config);
  g_input_error = py::module_::import("growbench").attr("InputError").ptr();
}

}  // namespace

// The table of the algorithm the script at `path` defines, or NULL with the reason in `error` (at most
// `error_size` bytes). Each script gets one table for the life of the process.
extern "C" GROWBENCH_PLUGIN_EXPORT const growbench_plugin* growbench_python_plugin(const char* path, char* error,
                                                                                   std::size_t error_size) {
  auto say = [&](const std::string& why) {
    if (error_size > 0) std::snprintf(error, error_size, "%s", why.c_str());
    return nullptr;
  };
  int slot = 0;
  while (slot < kSlots && g_scripts[slot]) ++slot;
  if (slot == kSlots) return say("more than 8 Python algorithms in one process");
  try {
    if (!Py_IsInitialized()) start_interpreter();
    auto sc = std::make_unique<Script>();
    sc->cls = load_class(path, slot);
    fill_table(*sc, slot);
    g_scripts[slot] = sc.release();
    return &g_scripts[slot]->table;
  } catch (const std::exception& e) {
    return say(e.what());
  }
}
