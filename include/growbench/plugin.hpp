// The C++ face of the growbench plugin ABI (plugin.h): write one class, export it with one macro.
//
//   #include <growbench/plugin.hpp>
//   namespace sdk = growbench::sdk;
//   class Walker final : public sdk::Algorithm {
//    public:
//     static sdk::Info info() {
//       return {"walker", "a random walk that clings to surfaces", "1.0",
//               {sdk::real("step", 0.01).range(1e-4, 1).unit("m").doc("length of one move")}};
//     }
//     void start(const sdk::Context& c) override { step_ = c.params.real("step"); ... }
//     bool step() override { ...; plant.add_node(...); return more; }
//   };
//   GROWBENCH_PLUGIN(Walker)
//
// Header-only and C++17. Exceptions never cross the boundary: the macro turns sdk::InputError into an
// invalid-input trial and any other std::exception into a failed one, with its message.
#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <exception>
#include <initializer_list>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "growbench/plugin.h"

namespace growbench::sdk {

using Vec3 = growbench_vec3;
inline Vec3 vec3(float x, float y, float z) {
  return Vec3{x, y, z};
}

// Thrown for parameters or a scene the algorithm cannot work with (the trial becomes invalid_input).
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// ------------------------------------------------------------------ the parameter table

// One row, built by name as the built-ins' tables are: real("step", 0.01).range(0, 1).unit("m").doc("...")
class Param {
 public:
  Param(std::string name, growbench_param_type type) : name_(std::move(name)), type_(type) {}
  Param&& range(double min, double max) && {
    min_ = min;
    max_ = max;
    return std::move(*this);
  }
  Param&& unit(std::string unit) && {
    unit_ = std::move(unit);
    return std::move(*this);
  }
  Param&& doc(std::string doc) && {
    doc_ = std::move(doc);
    return std::move(*this);
  }

 private:
  friend class Info;
  friend Param integer(std::string, std::int64_t);
  friend Param real(std::string, double);
  friend Param boolean(std::string, bool);
  friend Param text(std::string, std::string);
  friend Param vector3(std::string, double, double, double);
  friend Param choice(std::string, std::string, std::vector<std::string>);
  std::string name_;
  growbench_param_type type_;
  growbench_value default_{};
  std::string default_text_;
  double min_ = -HUGE_VAL, max_ = HUGE_VAL;
  std::string unit_, doc_;
  std::vector<std::string> choices_;
};

inline Param integer(std::string name, std::int64_t value) {
  Param p(std::move(name), GROWBENCH_PARAM_INT);
  p.default_.integer = value;
  return p;
}
inline Param real(std::string name, double value) {
  Param p(std::move(name), GROWBENCH_PARAM_REAL);
  p.default_.real = value;
  return p;
}
inline Param boolean(std::string name, bool value) {
  Param p(std::move(name), GROWBENCH_PARAM_BOOL);
  p.default_.boolean = value ? 1 : 0;
  return p;
}
inline Param text(std::string name, std::string value = {}) {
  Param p(std::move(name), GROWBENCH_PARAM_STRING);
  p.default_text_ = std::move(value);
  return p;
}
inline Param vector3(std::string name, double x, double y, double z) {
  Param p(std::move(name), GROWBENCH_PARAM_VEC3);
  p.default_.vec3[0] = x;
  p.default_.vec3[1] = y;
  p.default_.vec3[2] = z;
  return p;
}
inline Param choice(std::string name, std::string value, std::vector<std::string> choices) {
  Param p(std::move(name), GROWBENCH_PARAM_CHOICE);
  p.default_text_ = std::move(value);
  p.choices_ = std::move(choices);
  return p;
}

// What the plugin says about itself: growbench_plugin's descriptive members, owning their strings.
class Info {
 public:
  Info(std::string name, std::string summary, std::string version, std::vector<Param> params,
       std::vector<std::string> test_params = {})
      : name_(std::move(name)),
        summary_(std::move(summary)),
        version_(std::move(version)),
        params_(std::move(params)),
        test_params_(std::move(test_params)) {}
  Info(const Info&) = delete;  // the C table points into it
  Info& operator=(const Info&) = delete;
  Info(Info&&) = default;

  // Fills the descriptive members of `t`, pointing into this object, which must outlive `t`.
  void fill(growbench_plugin& t) {
    rows_.clear();
    choice_ptrs_.clear();
    for (const Param& p : params_) {
      growbench_param r{};
      r.name = p.name_.c_str();
      r.type = p.type_;
      r.default_value = p.default_;
      if (p.type_ == GROWBENCH_PARAM_STRING || p.type_ == GROWBENCH_PARAM_CHOICE)
        r.default_value.text = p.default_text_.c_str();
      r.min = p.min_;
      r.max = p.max_;
      r.unit = p.unit_.c_str();
      r.doc = p.doc_.c_str();
      auto& ptrs = choice_ptrs_.emplace_back();
      for (const auto& c : p.choices_) ptrs.push_back(c.c_str());
      r.choices = ptrs.data();
      r.choice_count = static_cast<std::uint32_t>(ptrs.size());
      rows_.push_back(r);
    }
    test_ptrs_.clear();
    for (const auto& a : test_params_) test_ptrs_.push_back(a.c_str());
    t.name = name_.c_str();
    t.summary = summary_.c_str();
    t.version = version_.c_str();
    t.params = rows_.data();
    t.param_count = static_cast<std::uint32_t>(rows_.size());
    t.test_params = test_ptrs_.data();
    t.test_param_count = static_cast<std::uint32_t>(test_ptrs_.size());
  }
  [[nodiscard]] const std::vector<Param>& params() const { return params_; }
  [[nodiscard]] std::size_t index_of(const std::string& key) const {
    for (std::size_t i = 0; i < params_.size(); ++i)
      if (params_[i].name_ == key) return i;
    throw std::logic_error("plugin '" + name_ + "' reads parameter '" + key + "', which its table does not have");
  }
  [[nodiscard]] growbench_param_type type_of(std::size_t i) const { return params_[i].type_; }

 private:
  std::string name_, summary_, version_;
  std::vector<Param> params_;
  std::vector<std::string> test_params_;
  std::vector<growbench_param> rows_;
  std::deque<std::vector<const char*>> choice_ptrs_;  // a deque: growing it never moves a row's array
  std::vector<const char*> test_ptrs_;
};

// The validated values start() receives, by name.
class Params {
 public:
  Params(const Info& info, const growbench_value* values) : info_(&info), values_(values) {}
  [[nodiscard]] std::int64_t integer(const std::string& key) const { return at(key, GROWBENCH_PARAM_INT).integer; }
  [[nodiscard]] double real(const std::string& key) const { return at(key, GROWBENCH_PARAM_REAL).real; }
  [[nodiscard]] bool boolean(const std::string& key) const { return at(key, GROWBENCH_PARAM_BOOL).boolean != 0; }
  // STRING and CHOICE; copied, as the values live only during start().
  [[nodiscard]] std::string text(const std::string& key) const {
    const std::size_t i = info_->index_of(key);
    if (info_->type_of(i) != GROWBENCH_PARAM_STRING && info_->type_of(i) != GROWBENCH_PARAM_CHOICE)
      throw std::logic_error("parameter '" + key + "' is not a string or choice");
    return values_[i].text ? values_[i].text : "";
  }
  [[nodiscard]] Vec3 vec3(const std::string& key) const {
    const auto v = vector3(key);
    return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])};
  }
  // The same in the doubles the host validated.
  [[nodiscard]] std::array<double, 3> vector3(const std::string& key) const {
    const double* v = at(key, GROWBENCH_PARAM_VEC3).vec3;
    return {v[0], v[1], v[2]};
  }

 private:
  [[nodiscard]] const growbench_value& at(const std::string& key, growbench_param_type type) const {
    const std::size_t i = info_->index_of(key);
    if (info_->type_of(i) != type) throw std::logic_error("parameter '" + key + "' is read with the wrong type");
    return values_[i];
  }
  const Info* info_;
  const growbench_value* values_;
};

// ------------------------------------------------------------------ the host

// The host's table with C++ conveniences. The batched calls are the fast ones: one call per array, not
// per point. Every call is safe from several threads.
class Host {
 public:
  explicit Host(const growbench_host* h) : h_(h) {}
  [[nodiscard]] const growbench_host& table() const { return *h_; }
  [[nodiscard]] unsigned threads() const { return h_->threads; }

  void log(const std::string& line) const { h_->log(h_->context, GROWBENCH_LOG_INFO, line.c_str()); }
  void warn(const std::string& line) const { h_->log(h_->context, GROWBENCH_LOG_WARNING, line.c_str()); }
  [[nodiscard]] bool cancelled() const { return h_->cancelled(h_->context) != 0; }

  // Counter-based random numbers from the trial's seed.
  [[nodiscard]] std::uint64_t bits(std::uint64_t stream, std::uint64_t counter) const {
    return h_->random_bits(h_->context, stream, counter);
  }
  // Uniform in [0, 1), 53 bits.
  [[nodiscard]] double uniform(std::uint64_t stream, std::uint64_t counter) const {
    return static_cast<double>(bits(stream, counter) >> 11) * 0x1.0p-53;
  }

  void closest_points(const Vec3* p, std::size_t n, growbench_closest_hit* out, float max_distance = HUGE_VALF,
                      bool climbable_only = false) const {
    h_->closest_points(h_->context, p, n, max_distance, climbable_only ? 1 : 0, out);
  }
  [[nodiscard]] growbench_closest_hit closest_point(const Vec3& p, float max_distance = HUGE_VALF,
                                                    bool climbable_only = false) const {
    growbench_closest_hit hit{};
    closest_points(&p, 1, &hit, max_distance, climbable_only);
    return hit;
  }
  void rays(const growbench_ray* r, std::size_t n, growbench_ray_hit* out) const { h_->rays(h_->context, r, n, out); }
  [[nodiscard]] growbench_ray_hit ray(const Vec3& origin, const Vec3& dir, float tmax = HUGE_VALF,
                                      float tmin = 0.0f) const {
    const growbench_ray r{origin, dir, tmin, tmax};
    growbench_ray_hit hit{};
    rays(&r, 1, &hit);
    return hit;
  }
  void occluded(const growbench_ray* r, std::size_t n, std::uint8_t* out) const {
    h_->occluded(h_->context, r, n, out);
  }
  // Throws InputError when the scene has no distance field. Either output may be null.
  void signed_distance(const Vec3* p, std::size_t n, float* distance, Vec3* gradient = nullptr) const {
    if (h_->signed_distance(h_->context, p, n, distance, gradient) != GROWBENCH_OK)
      throw InputError("the scene has no distance field");
  }
  [[nodiscard]] float signed_distance(const Vec3& p, Vec3* gradient = nullptr) const {
    float d = 0.0f;
    signed_distance(&p, 1, &d, gradient);
    return d;
  }
  void inside(const Vec3* p, std::size_t n, std::uint8_t* out) const { h_->inside(h_->context, p, n, out); }
  [[nodiscard]] bool inside(const Vec3& p) const {
    std::uint8_t r = 0;
    inside(&p, 1, &r);
    return r != 0;
  }
  void inside_shape(int shape, const Vec3* p, std::size_t n, std::uint8_t* out) const {
    h_->inside_shape(h_->context, shape, p, n, out);
  }
  void sample_surface(std::uint64_t seed, std::uint64_t first, std::size_t n, growbench_surface_sample* out) const {
    h_->sample_surface(h_->context, seed, first, n, out);
  }
  void light_visible(const Vec3* p, std::size_t n, std::uint8_t* out, float bias = 1e-4f) const {
    h_->light_visible(h_->context, p, n, bias, out);
  }

  // body(chunk_begin, chunk_end) over disjoint chunks covering [begin, end), on the trial's threads. The
  // chunks depend only on (begin, end, grain), so results written per index are the same for any thread
  // count. An exception from body is kept (the first one) and rethrown here after every chunk has run.
  template <class F>
  void parallel_for(std::uint64_t begin, std::uint64_t end, F&& body, std::uint64_t grain = 0) const {
    struct Call {
      std::remove_reference_t<F>* body;
      std::exception_ptr error;
      std::atomic<bool> failed{false};
    } call{&body, nullptr};
    h_->parallel_for(
        h_->context, begin, end, grain,
        [](void* user, std::uint64_t b, std::uint64_t e) {
          auto& c = *static_cast<Call*>(user);
          try {
            (*c.body)(b, e);
          } catch (...) {
            if (!c.failed.exchange(true)) c.error = std::current_exception();
          }
        },
        &call);
    if (call.error) std::rethrow_exception(call.error);
  }

  // A scene mesh's texture coordinates (see growbench_host::mesh_uvs); empty (count 0) when it has none.
  struct MeshUvs {
    const float* uvs = nullptr;  // 2 per coordinate: u, v
    std::uint64_t count = 0;
    const std::uint32_t* triangles = nullptr;  // 3 coordinate indices per triangle of the mesh
  };
  [[nodiscard]] MeshUvs mesh_uvs(std::uint32_t mesh) const {
    MeshUvs m;
    if (h_->mesh_uvs(h_->context, mesh, &m.uvs, &m.count, &m.triangles) == 0) return {};
    return m;
  }
  // Texture coordinates, face normal and tangents at points on scene triangles.
  void surface_frames(const growbench_surface_point* p, std::size_t n, growbench_surface_frame* out) const {
    h_->surface_frames(h_->context, p, n, out);
  }

 private:
  const growbench_host* h_;
};

// What start() is given. The scene and host live until the instance is destroyed; params only during start().
struct Context {
  const growbench_scene& scene;
  Host host;
  Params params;
  std::uint64_t seed;
};

// ------------------------------------------------------------------ the plant

// A named value per node (see growbench_attribute): "Cd" with 3 components colours the branches.
struct Attribute {
  std::string name;
  std::uint32_t components = 1;
  std::vector<float> values;  // nodes.size() * components, node by node
};

// An image laid over the scene's surfaces (see growbench_decal): over a mesh's texture coordinates, or
// planar (mesh GROWBENCH_PLANAR_DECAL) at origin + u * u_axis + v * v_axis.
struct Decal {
  std::int32_t mesh = GROWBENCH_PLANAR_DECAL;
  Vec3 origin{0.0f, 0.0f, 0.0f}, u_axis{1.0f, 0.0f, 0.0f}, v_axis{0.0f, 1.0f, 0.0f};
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // width * height * 4, sRGB with straight alpha, the top row (v = 1) first
};

// The plant as the plugin builds it; view() hands it to the host without a copy.
struct Plant {
  std::vector<growbench_node> nodes;
  std::vector<growbench_organ> organs;
  std::vector<Vec3> polygon_vertices;
  std::vector<std::uint64_t> polygon_offsets;  // polygon_offsets.size() == polygons + 1, or empty
  // The shapes organs name: built-in shape names ("leaf", "blossom", "half_bloom", "bud") or OBJ paths.
  std::vector<std::string> organ_shapes;
  // Per organ, or empty: an index into organ_shapes (GROWBENCH_KIND_SHAPE: its kind's shape), and a
  // colour factor on its shape's colour (each component in [0, 4]).
  std::vector<std::uint16_t> organ_shape;
  std::vector<Vec3> organ_tint;
  std::deque<Attribute> attributes;  // a deque: attribute() never moves one already made
  // Per node, or empty: its group (-1: none); group g's branches are the mesh part group_prefix + g.
  std::vector<std::int32_t> node_groups;
  std::string group_prefix;
  std::vector<Decal> decals;

  // Appends an organ and, when given, its shape (an index into organ_shapes) and tint.
  void add_organ(const growbench_organ& organ, std::uint16_t shape = GROWBENCH_KIND_SHAPE,
                 Vec3 tint = Vec3{1.0f, 1.0f, 1.0f}) {
    organs.push_back(organ);
    organ_shape.resize(organs.size() - 1, GROWBENCH_KIND_SHAPE);
    organ_tint.resize(organs.size() - 1, Vec3{1.0f, 1.0f, 1.0f});
    organ_shape.push_back(shape);
    organ_tint.push_back(tint);
  }
  // The attribute `name`, made with `components` per node when new; its values grow with the nodes.
  Attribute& attribute(const std::string& name, std::uint32_t components = 1) {
    for (auto& a : attributes)
      if (a.name == name) return a;
    attributes.push_back({name, components, {}});
    return attributes.back();
  }

  // Appends a node and returns its index.
  std::int32_t add_node(const Vec3& position, float radius, std::int32_t parent, std::uint32_t order,
                        std::uint32_t shoot, std::uint32_t birth_step) {
    nodes.push_back({position, radius, parent, order, shoot, birth_step});
    return static_cast<std::int32_t>(nodes.size() - 1);
  }
  void add_polygon(std::initializer_list<Vec3> vertices) {
    if (polygon_offsets.empty()) polygon_offsets.push_back(0);
    polygon_vertices.insert(polygon_vertices.end(), vertices.begin(), vertices.end());
    polygon_offsets.push_back(polygon_vertices.size());
  }
  // The view of the plant. Per-organ arrays shorter than organs are padded, and attributes padded or cut to
  // the node count, so the host never reads past them.
  [[nodiscard]] growbench_plant_view view() const {
    growbench_plant_view v{};
    v.nodes = nodes.data();
    v.node_count = nodes.size();
    v.organs = organs.data();
    v.organ_count = organs.size();
    v.polygon_vertices = polygon_vertices.data();
    v.polygon_offsets = polygon_offsets.empty() ? nullptr : polygon_offsets.data();
    v.polygon_count = polygon_offsets.empty() ? 0 : polygon_offsets.size() - 1;
    shape_ptrs_.clear();
    for (const auto& s : organ_shapes) shape_ptrs_.push_back(s.c_str());
    v.organ_shapes = shape_ptrs_.data();
    v.organ_shape_count = static_cast<std::uint32_t>(shape_ptrs_.size());
    v.organ_shape = per_organ(organ_shape, padded_shape_, std::uint16_t{GROWBENCH_KIND_SHAPE});
    v.organ_tint = per_organ(organ_tint, padded_tint_, Vec3{1.0f, 1.0f, 1.0f});
    attribute_views_.clear();
    padded_values_.resize(attributes.size());
    for (std::size_t k = 0; k < attributes.size(); ++k) {
      const Attribute& a = attributes[k];
      const float* values = a.values.data();
      if (a.values.size() != nodes.size() * a.components) {
        padded_values_[k] = a.values;
        padded_values_[k].resize(nodes.size() * a.components, 0.0f);
        values = padded_values_[k].data();
      }
      attribute_views_.push_back({a.name.c_str(), a.components, values});
    }
    v.node_attributes = attribute_views_.data();
    v.node_attribute_count = static_cast<std::uint32_t>(attribute_views_.size());
    if (!node_groups.empty()) {
      padded_groups_ = node_groups;
      padded_groups_.resize(nodes.size(), -1);
      v.node_groups = padded_groups_.data();
    }
    v.group_prefix = group_prefix.c_str();
    decal_views_.clear();
    for (const Decal& d : decals) {
      if (d.rgba.size() != std::size_t{d.width} * d.height * 4)
        throw std::length_error("decal of " + std::to_string(d.width) + " x " + std::to_string(d.height) +
                                " pixels holds " + std::to_string(d.rgba.size()) + " bytes, not 4 per pixel");
      decal_views_.push_back({d.mesh, d.origin, d.u_axis, d.v_axis, d.width, d.height, d.rgba.data()});
    }
    v.decals = decal_views_.data();
    v.decal_count = static_cast<std::uint32_t>(decal_views_.size());
    return v;
  }

 private:
  // `given` as an array of organs.size(), padded with `fill` into `padded` when shorter; null when empty.
  template <class T>
  const T* per_organ(const std::vector<T>& given, std::vector<T>& padded, T fill) const {
    if (given.empty()) return nullptr;
    if (given.size() == organs.size()) return given.data();
    padded = given;
    padded.resize(organs.size(), fill);
    return padded.data();
  }
  mutable std::vector<const char*> shape_ptrs_;
  mutable std::vector<growbench_attribute> attribute_views_;
  mutable std::vector<std::uint16_t> padded_shape_;
  mutable std::vector<Vec3> padded_tint_;
  mutable std::vector<std::vector<float>> padded_values_;
  mutable std::vector<std::int32_t> padded_groups_;
  mutable std::vector<growbench_decal> decal_views_;
};

// ------------------------------------------------------------------ the algorithm

class Algorithm {
 public:
  virtual ~Algorithm() = default;
  virtual void start(const Context& context) = 0;
  // One growth step; false when growth has ended by itself.
  virtual bool step() = 0;
  // After the last step (pipe radii, leaves).
  virtual void finish() {}
  // Algorithm-specific figures for the record.
  [[nodiscard]] virtual std::vector<std::pair<std::string, double>> stats() const { return {}; }
  // The plant as it stands. An algorithm that assembles its plant on demand overrides it.
  [[nodiscard]] virtual const Plant& current_plant() { return plant; }
  // The node and organ counts the host reads after every step; override when current_plant() is costly.
  [[nodiscard]] virtual std::pair<std::uint64_t, std::uint64_t> counts() {
    const Plant& p = current_plant();
    return {p.nodes.size(), p.organs.size()};
  }

 protected:
  Plant plant;
};

namespace detail {

struct Instance {
  const growbench_host* host;
  std::unique_ptr<Algorithm> algorithm;
  std::vector<std::string> stat_names;
  std::vector<growbench_stat> stats;
};

inline int32_t report(const growbench_host* host, int32_t status, const char* message) {
  if (host && host->fail) host->fail(host->context, message);
  return status;
}

// Runs `f`, turning exceptions into a status and a message for the host.
template <class F>
int32_t guarded(const growbench_host* host, F&& f) {
  try {
    return f();
  } catch (const InputError& e) {
    return report(host, GROWBENCH_INPUT_ERROR, e.what());
  } catch (const std::bad_alloc& e) {
    return report(host, GROWBENCH_OUT_OF_MEMORY, e.what());
  } catch (const std::exception& e) {
    return report(host, GROWBENCH_ERROR, e.what());
  } catch (...) {
    return report(host, GROWBENCH_ERROR, "unknown exception");
  }
}

template <class A>
struct Exported {
  static Info& info() {
    static Info i = A::info();
    return i;
  }
  static growbench_instance* create(const growbench_host* host) {
    auto* inst = new (std::nothrow) Instance{host, nullptr, {}, {}};
    if (!inst) return nullptr;
    const int32_t s = guarded(host, [&] {
      inst->algorithm = std::make_unique<A>();
      return int32_t{GROWBENCH_OK};
    });
    if (s != GROWBENCH_OK) {
      delete inst;
      return nullptr;
    }
    return reinterpret_cast<growbench_instance*>(inst);
  }
  static Instance& self(growbench_instance* i) { return *reinterpret_cast<Instance*>(i); }
  static int32_t start(growbench_instance* i, const growbench_scene* scene, const growbench_value* values,
                       uint64_t seed) {
    Instance& s = self(i);
    return guarded(s.host, [&] {
      s.algorithm->start(Context{*scene, Host(s.host), Params(info(), values), seed});
      return int32_t{GROWBENCH_OK};
    });
  }
  static int32_t step(growbench_instance* i) {
    Instance& s = self(i);
    bool more = false;
    const int32_t r = guarded(s.host, [&] {
      more = s.algorithm->step();
      return int32_t{GROWBENCH_OK};
    });
    return r != GROWBENCH_OK ? -r : (more ? 1 : 0);
  }
  static int32_t finish(growbench_instance* i) {
    Instance& s = self(i);
    return guarded(s.host, [&] {
      s.algorithm->finish();
      return int32_t{GROWBENCH_OK};
    });
  }
  static int32_t plant(growbench_instance* i, growbench_plant_view* out) {
    Instance& s = self(i);
    return guarded(s.host, [&] {
      *out = s.algorithm->current_plant().view();
      return int32_t{GROWBENCH_OK};
    });
  }
  static void counts(growbench_instance* i, uint64_t* nodes, uint64_t* organs) {
    Instance& s = self(i);
    *nodes = *organs = 0;
    guarded(s.host, [&] {
      std::tie(*nodes, *organs) = s.algorithm->counts();
      return int32_t{GROWBENCH_OK};
    });
  }
  static uint32_t stats(growbench_instance* i, const growbench_stat** out) {
    Instance& s = self(i);
    s.stat_names.clear();
    s.stats.clear();
    const int32_t r = guarded(s.host, [&] {
      for (auto& [k, v] : s.algorithm->stats()) s.stat_names.push_back(k), s.stats.push_back({nullptr, v});
      return int32_t{GROWBENCH_OK};
    });
    if (r != GROWBENCH_OK) s.stats.clear();
    for (std::size_t k = 0; k < s.stats.size(); ++k) s.stats[k].name = s.stat_names[k].c_str();
    *out = s.stats.data();
    return static_cast<uint32_t>(s.stats.size());
  }
  static void destroy(growbench_instance* i) { delete reinterpret_cast<Instance*>(i); }

  static const growbench_plugin* table() {
    static growbench_plugin t = [] {
      growbench_plugin p{};
      p.abi_version = GROWBENCH_PLUGIN_ABI_VERSION;
      p.struct_size = sizeof(growbench_plugin);
      info().fill(p);
      p.create = &create;
      p.start = &start;
      p.step = &step;
      p.finish = &finish;
      p.plant = &plant;
      p.counts = &counts;
      p.stats = &stats;
      p.destroy = &destroy;
      return p;
    }();
    return &t;
  }
};

}  // namespace detail
}  // namespace growbench::sdk

// Exports CLASS (an sdk::Algorithm with a static info() and a default constructor) as the library's
// plugin. Use it once, at global scope, in one source file.
#define GROWBENCH_PLUGIN(CLASS)                                                             \
  extern "C" GROWBENCH_PLUGIN_EXPORT const growbench_plugin* growbench_plugin_entry(void) { \
    return ::growbench::sdk::detail::Exported<CLASS>::table();                              \
  }
