// The host's side of the plugin ABI: the scene and the queries handed to the plugin as plain arrays and
// C functions, and its plant copied back into a Plant.
#include "algorithms/plugins/plugin_algorithm.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <mutex>
#include <new>
#include <stdexcept>

#include <fmt/format.h>
#include <stb_image_write.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "algorithms/organ_shapes.hpp"
#include "algorithms/plugins/abi_convert.hpp"
#include "core/errors.hpp"
#include "core/outcome.hpp"
#include "core/random.hpp"

namespace growbench {
namespace {

// What a plugin's status says of how its call ended (include/growbench/plugin.h): its own failure, and any
// status the ABI does not define, is the plugin's error, not growbench's.
Outcome outcome_of_status(std::int32_t status) {
  switch (status) {
    case GROWBENCH_OK:
      return Outcome::ok;
    case GROWBENCH_INPUT_ERROR:
      return Outcome::invalid_input;
    case GROWBENCH_OUT_OF_MEMORY:
      return Outcome::out_of_memory;
    default:
      return Outcome::plugin_error;
  }
}

using abi::points;

growbench_mesh mesh_view(const TriangleMesh& m, bool solid) {
  return {m.name.c_str(),     abi::of(m.vertices.data()),
          m.vertices.size(),  reinterpret_cast<const std::uint32_t*>(m.triangles.data()),
          m.triangles.size(), m.climbable ? 1 : 0,
          solid ? 1 : 0};
}

growbench_shape shape_view(const Shape& s) {
  growbench_shape v{};
  const Aabb b = s.bounds();
  v.kind = s.kind == Shape::Kind::Box      ? GROWBENCH_SHAPE_BOX
           : s.kind == Shape::Kind::Sphere ? GROWBENCH_SHAPE_ELLIPSOID
                                           : GROWBENCH_SHAPE_MESH;
  v.min = abi::of(s.kind == Shape::Kind::Box ? s.min : b.min);
  v.max = abi::of(s.kind == Shape::Kind::Box ? s.max : b.max);
  v.center = abi::of(s.center);
  v.radii = abi::of(s.radii);
  if (s.kind == Shape::Kind::Mesh) v.mesh = mesh_view(s.mesh, true);
  return v;
}

// The texture coordinates and surface frame at p on triangle t of m, which has them (growbench_surface_frame).
growbench_surface_frame surface_frame(const TriangleMesh& m, std::uint32_t t, const glm::vec3& p) {
  const glm::uvec3 c = m.triangles[t], k = m.uv_triangles[t];
  const glm::vec3 a = m.vertices[c.x], e1 = m.vertices[c.y] - a, e2 = m.vertices[c.z] - a;
  const glm::vec2 ta = m.uvs[k.x], d1 = m.uvs[k.y] - ta, d2 = m.uvs[k.z] - ta;
  growbench_surface_frame f{};
  // Barycentric coordinates of p's projection onto the triangle's plane (in double: slivers are common).
  const glm::dvec3 de1(e1), de2(e2), dp = glm::dvec3(p) - glm::dvec3(a);
  const double d11 = glm::dot(de1, de1), d12 = glm::dot(de1, de2), d22 = glm::dot(de2, de2);
  const double det = d11 * d22 - d12 * d12;
  if (!(det > 0.0)) return f;  // a degenerate triangle has no frame
  const double p1 = glm::dot(dp, de1), p2 = glm::dot(dp, de2);
  const double b1 = (d22 * p1 - d12 * p2) / det, b2 = (d11 * p2 - d12 * p1) / det;
  const glm::dvec2 uv = glm::dvec2(ta) + b1 * glm::dvec2(d1) + b2 * glm::dvec2(d2);
  f.found = 1;
  f.u = static_cast<float>(uv.x);
  f.v = static_cast<float>(uv.y);
  f.normal = abi::of(glm::normalize(glm::cross(e1, e2)));
  // dp/du and dp/dv from e1 = dp_du d1.x + dp_dv d1.y and e2 likewise; zero where the UVs are degenerate.
  const float uv_det = d1.x * d2.y - d2.x * d1.y;
  if (uv_det != 0.0f && std::isfinite(1.0f / uv_det)) {
    f.dp_du = abi::of((e1 * d2.y - e2 * d1.y) / uv_det);
    f.dp_dv = abi::of((e2 * d1.x - e1 * d2.x) / uv_det);
  }
  return f;
}

bool is_name_part(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

class PluginAlgorithm final : public GrowthAlgorithm {
 public:
  PluginAlgorithm(const growbench_plugin* t, const AlgorithmInfo& info, const std::string& path)
      : t_(t), info_(info), who_(fmt::format("algorithm '{}' (plugin {})", info.name, path)) {}
  ~PluginAlgorithm() override {
    if (inst_) t_->destroy(inst_);
  }
  PluginAlgorithm(const PluginAlgorithm&) = delete;
  PluginAlgorithm& operator=(const PluginAlgorithm&) = delete;

  const AlgorithmInfo& describe() const override { return info_; }

  void start(const Scene& scene, const SceneQuery& query, const Params& params, std::uint64_t seed) override {
    q_ = &query.host_queries();
    scene_in_ = &scene;
    seed_ = seed;
    describe_scene(scene, query);
    make_host();
    std::vector<growbench_value> values = read_values(params);
    inst_ = t_->create(&host_);
    if (!inst_) raise(GROWBENCH_ERROR, "create");
    check(t_->start(inst_, &scene_, values.data(), seed), "start");
  }

  bool step() override {
    const std::int32_t r = t_->step(inst_);
    ++version_;
    check_host_error("step");
    if (r < 0) raise(-r, "step");
    if (r > 1) raise(GROWBENCH_ERROR, fmt::format("step (returned {}, expected 1, 0 or an error)", r));
    return r == 1;
  }

  void finish() override {
    check(t_->finish(inst_), "finish");
    check_host_error("finish");
    ++version_;
  }

  const Plant& plant() const override {
    if (plant_version_ != version_) {
      growbench_plant_view v{};
      check(t_->plant(inst_, &v), "plant");
      copy_plant(v);
      plant_version_ = version_;
    }
    return plant_;
  }

  std::size_t node_count() const override { return counts().first; }
  std::size_t organ_count() const override { return counts().second; }

  std::vector<OutputFile> write_outputs(const OutputRequest& r) const override {
    const Plant& p = plant();
    std::vector<OutputFile> out;
    for (std::size_t k = 0; k < p.decals.size(); ++k) {
      const std::string name = r.prefix + p.decals[k].image;
      const std::string path = (std::filesystem::path(r.dir) / name).string();
      const auto [w, h] = decal_sizes_[k];
      if (stbi_write_png(path.c_str(), w, h, 4, decal_pixels_[k].data(), w * 4) == 0)
        throw std::runtime_error(fmt::format("{}: cannot write the decal image {}", who_, path));
      out.push_back({name, static_cast<std::uint64_t>(std::filesystem::file_size(path))});
    }
    return out;
  }

  std::vector<std::pair<std::string, double>> stats() const override {
    std::vector<std::pair<std::string, double>> out;
    if (!t_->stats) return out;
    const growbench_stat* s = nullptr;
    const std::uint32_t n = t_->stats(inst_, &s);
    for (std::uint32_t i = 0; i < n && s; ++i)
      if (s[i].name) out.emplace_back(s[i].name, s[i].value);
    return out;
  }

 private:
  std::pair<std::size_t, std::size_t> counts() const {
    if (!t_->counts) {  // the view's sizes: no copy of the plant after every step
      if (plant_version_ == version_) return {plant_.nodes.size(), plant_.organs.size()};
      growbench_plant_view v{};
      check(t_->plant(inst_, &v), "plant");
      return {static_cast<std::size_t>(v.node_count), static_cast<std::size_t>(v.organ_count)};
    }
    std::uint64_t nodes = 0, organs = 0;
    t_->counts(inst_, &nodes, &organs);
    return {static_cast<std::size_t>(nodes), static_cast<std::size_t>(organs)};
  }

  // The scene as arrays that point into `scene`, which outlives the algorithm.
  void describe_scene(const Scene& scene, const SceneQuery& query) {
    meshes_.clear();
    for (std::size_t i = 0; i < scene.meshes.size(); ++i)
      meshes_.push_back(mesh_view(scene.meshes[i], query.mesh_solid()[i]));
    seeds_.clear();
    for (const auto& s : scene.seeds) seeds_.push_back({abi::of(s.position), abi::of(s.direction), s.start_step});
    zones_.clear();
    for (const auto& z : scene.zones)
      zones_.push_back({static_cast<std::int32_t>(z.kind), shape_view(z.shape), z.strength});
    scene_ = {};
    scene_.name = scene.name.c_str();
    scene_.meshes = meshes_.data();
    scene_.mesh_count = static_cast<std::uint32_t>(meshes_.size());
    scene_.seeds = seeds_.data();
    scene_.seed_count = static_cast<std::uint32_t>(seeds_.size());
    scene_.light = {scene.light.kind == Light::Kind::Point ? 1 : 0, abi::of(scene.light.direction),
                    abi::of(scene.light.position)};
    scene_.has_envelope = scene.envelope ? 1 : 0;
    if (scene.envelope) scene_.envelope = shape_view(*scene.envelope);
    scene_.zones = zones_.data();
    scene_.zone_count = static_cast<std::uint32_t>(zones_.size());
    const Aabb b = scene.bounds();
    scene_.bounds_min = abi::of(b.min);
    scene_.bounds_max = abi::of(b.max);
    scene_.has_sdf = query.has_sdf() ? 1 : 0;
    scene_.voxel_size = query.voxel_size();
  }

  static_assert(static_cast<int>(Zone::Kind::Attract) == GROWBENCH_ZONE_ATTRACT &&
                static_cast<int>(Zone::Kind::Repel) == GROWBENCH_ZONE_REPEL &&
                static_cast<int>(Zone::Kind::Include) == GROWBENCH_ZONE_INCLUDE &&
                static_cast<int>(Zone::Kind::Exclude) == GROWBENCH_ZONE_EXCLUDE);

  // The values in the table's order; strings point into `params`, which outlives start().
  static std::vector<growbench_value> read_values(const Params& params) {
    std::vector<growbench_value> v;
    for (const ParamSpec& s : params.specs()) {
      growbench_value x{};
      switch (s.type) {
        case ParamType::Int:
          x.integer = params.integer(s.name);
          break;
        case ParamType::Real:
          x.real = params.real(s.name);
          break;
        case ParamType::Bool:
          x.boolean = params.boolean(s.name) ? 1 : 0;
          break;
        case ParamType::String:
        case ParamType::Choice:
          x.text = params.text(s.name).c_str();
          break;
        case ParamType::Vec3: {
          const glm::dvec3 d = params.vec3(s.name);
          x.vec3[0] = d.x;
          x.vec3[1] = d.y;
          x.vec3[2] = d.z;
          break;
        }
      }
      v.push_back(x);
    }
    return v;
  }

  void make_host();

  [[noreturn]] void raise(std::int32_t status, const std::string& where) const {
    std::string message;
    {
      std::lock_guard lock(fail_mutex_);
      message = failure_.empty() ? "no message given" : failure_;
      failure_.clear();
    }
    throw_as(outcome_of_status(status), fmt::format("{} failed in {}: {}", who_, where, message));
  }
  void check(std::int32_t status, const std::string& where) const {
    if (status != GROWBENCH_OK) raise(status, where);
  }
  void check_host_error(const std::string& where) const {
    std::lock_guard lock(fail_mutex_);
    if (!host_error_.empty()) throw std::runtime_error(fmt::format("{} in {}: {}", who_, where, host_error_));
  }

  void copy_plant(const growbench_plant_view& v) const {
    auto bad = [&](const std::string& what) { return malformed(what); };
    if ((v.node_count && !v.nodes) || (v.organ_count && !v.organs)) throw bad("a NULL array with a non-zero count");
    plant_.clear();
    plant_.nodes.reserve(v.node_count);
    for (std::uint64_t i = 0; i < v.node_count; ++i) {
      const growbench_node& n = v.nodes[i];
      if (n.order > 0xFFFFu) throw bad(fmt::format("node {} has branch order {} (at most 65535)", i, n.order));
      plant_.nodes.push_back(
          {abi::of(n.position), n.radius, n.parent, static_cast<std::uint16_t>(n.order), n.shoot, n.birth_step});
    }
    plant_.organs.reserve(v.organ_count);
    for (std::uint64_t i = 0; i < v.organ_count; ++i) {
      const growbench_organ& o = v.organs[i];
      if (o.kind < GROWBENCH_ORGAN_LEAF || o.kind > GROWBENCH_ORGAN_BUD)
        throw bad(fmt::format("organ {} has kind {}, not a growbench_organ_kind", i, o.kind));
      Organ g;
      g.position = abi::of(o.position);
      g.orientation = glm::quat(o.orientation[0], o.orientation[1], o.orientation[2], o.orientation[3]);
      g.size = o.size;
      g.kind = static_cast<OrganKind>(o.kind);
      g.node = o.node;
      g.stamp = {o.stamp[0], o.stamp[1], o.stamp[2]};
      plant_.organs.push_back(g);
    }
    copy_polygons(v);
    if (t_->abi_version >= 2) copy_styles(v);
    if (t_->abi_version >= 3) {
      copy_groups(v);
      copy_decals(v);
    }
  }

  // Version 3's node groups, checked as the L-system's g and group_prefix are.
  void copy_groups(const growbench_plant_view& v) const {
    const std::string prefix = v.group_prefix ? v.group_prefix : "";
    if (!std::all_of(prefix.begin(), prefix.end(), is_name_part) || prefix.size() > 64)
      throw malformed(
          fmt::format("group_prefix '{}' (expected letters, digits and '_', at most 64 bytes: it "
                      "names the meshes' groups)",
                      escape_utf8(prefix)));
    if (!v.node_groups) return;
    plant_.node_groups.assign(v.node_groups, v.node_groups + v.node_count);
    for (std::size_t i = 0; i < plant_.node_groups.size(); ++i)
      if (plant_.node_groups[i] < -1)
        throw malformed(
            fmt::format("node {} has group {} (expected -1 for none, or 0 and up)", i, plant_.node_groups[i]));
    plant_.group_prefix = prefix;
  }

  // Version 3's decals: the images are copied, and written as PNGs by write_outputs().
  void copy_decals(const growbench_plant_view& v) const {
    if (v.decal_count && !v.decals) throw malformed("a NULL array with a non-zero count");
    decal_pixels_.clear();
    decal_sizes_.clear();
    for (std::uint32_t k = 0; k < v.decal_count; ++k) {
      const growbench_decal& d = v.decals[k];
      if (const std::string why = decal_problem(d); !why.empty()) throw malformed(fmt::format("decal {} {}", k, why));
      SurfaceDecal s;
      s.image = fmt::format("decal{}.png", k);
      s.mesh = d.mesh;
      s.origin = abi::of(d.origin);
      s.u_axis = abi::of(d.u_axis);
      s.v_axis = abi::of(d.v_axis);
      plant_.decals.push_back(s);
      decal_pixels_.emplace_back(d.rgba, d.rgba + std::size_t{d.width} * d.height * 4);
      decal_sizes_.resize(k + 1);
      decal_sizes_[k] = {static_cast<int>(d.width), static_cast<int>(d.height)};
    }
  }

  [[nodiscard]] std::string decal_problem(const growbench_decal& d) const {
    constexpr std::uint32_t kMaxSide = 8192;
    if (d.width < 1 || d.height < 1 || d.width > kMaxSide || d.height > kMaxSide)
      return fmt::format("is {} x {} pixels (expected 1 to {} each way)", d.width, d.height, kMaxSide);
    if (!d.rgba) return "has no pixels (rgba is NULL)";
    const auto& meshes = scene_in_->meshes;
    if (d.mesh >= 0) {
      if (static_cast<std::size_t>(d.mesh) >= meshes.size())
        return fmt::format("follows mesh {}, but the scene has {} meshes", d.mesh, meshes.size());
      if (!meshes[static_cast<std::size_t>(d.mesh)].has_uvs())
        return fmt::format("follows mesh {} ('{}'), which has no texture coordinates", d.mesh,
                           escape_utf8(meshes[static_cast<std::size_t>(d.mesh)].name));
      return "";
    }
    if (d.mesh != GROWBENCH_PLANAR_DECAL)
      return fmt::format("has mesh {} (expected a mesh index, or GROWBENCH_PLANAR_DECAL)", d.mesh);
    const glm::vec3 o = abi::of(d.origin), u = abi::of(d.u_axis), w = abi::of(d.v_axis);
    const glm::vec3 n = glm::cross(u, w);
    if (!std::isfinite(glm::dot(o, o) + glm::dot(u, u) + glm::dot(w, w)) || !(glm::dot(n, n) > 0.0f))
      return "is planar with a non-finite origin or axes, or parallel axes";
    return "";
  }

  [[nodiscard]] PluginError malformed(const std::string& what) const {
    return PluginError(fmt::format("{} returned a malformed plant: {}", who_, what));
  }

  void copy_polygons(const growbench_plant_view& v) const {
    auto bad = [&](const std::string& what) { return malformed(what); };
    if (v.polygon_count == 0) return;
    if (!v.polygon_offsets || !v.polygon_vertices) throw bad("polygons without their arrays");
    if (v.polygon_offsets[0] != 0) throw bad("polygon_offsets[0] is not 0");
    for (std::uint64_t i = 0; i < v.polygon_count; ++i) {
      const std::uint64_t a = v.polygon_offsets[i], b = v.polygon_offsets[i + 1];
      if (b < a) throw bad(fmt::format("polygon_offsets decrease at polygon {}", i));
      PlantPolygon poly;
      for (std::uint64_t k = a; k < b; ++k) poly.vertices.push_back(abi::of(v.polygon_vertices[k]));
      plant_.polygons.push_back(std::move(poly));
    }
  }

  // Version 2's organ shapes and tints and named node attributes, checked as a built-in's are where they enter.
  void copy_styles(const growbench_plant_view& v) const {
    if ((v.organ_shape_count && !v.organ_shapes) || (v.node_attribute_count && !v.node_attributes))
      throw malformed("a NULL array with a non-zero count");
    for (std::uint32_t k = 0; k < v.organ_shape_count; ++k) {
      if (!v.organ_shapes[k]) throw malformed(fmt::format("organ shape {} is NULL", k));
      plant_.organ_shapes.emplace_back(v.organ_shapes[k]);
    }
    if (plant_.organ_shapes != checked_shapes_) {  // a shape is parsed (an OBJ read) once, not every step
      try {
        for (const auto& s : plant_.organ_shapes) (void)organ_shape_named(s, "organ_shapes");
      } catch (const InputError& e) {
        throw malformed(e.what());
      }
      checked_shapes_ = plant_.organ_shapes;
    }
    for (std::uint64_t i = 0; i < plant_.organs.size(); ++i) {
      if (v.organ_shape) plant_.organs[i].shape = v.organ_shape[i];
      if (v.organ_tint) plant_.organs[i].tint = abi::of(v.organ_tint[i]);
    }
    for (std::uint32_t k = 0; k < v.node_attribute_count; ++k) plant_.node_attributes.push_back(attribute(v, k));
  }

  [[nodiscard]] NodeAttribute attribute(const growbench_plant_view& v, std::uint32_t k) const {
    const growbench_attribute& a = v.node_attributes[k];
    const std::string name = a.name ? a.name : "";
    const bool named = !name.empty() && name.size() <= 64 &&
                       (std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_') &&
                       std::all_of(name.begin(), name.end(),
                                   [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
    if (!named)
      throw malformed(
          fmt::format("node attribute {} is named '{}' (expected a letter or '_', then letters, digits "
                      "and '_', at most 64 bytes)",
                      k, escape_utf8(name)));
    for (const auto& b : plant_.node_attributes)
      if (b.name == name) throw malformed(fmt::format("node attribute '{}' is given twice", name));
    if (a.components < 1 || a.components > 4 || (name == "Cd" && a.components != 3))
      throw malformed(
          fmt::format("node attribute '{}' has {} components (expected 1 to 4, and 3 for Cd)", name, a.components));
    if (v.node_count && !a.values) throw malformed(fmt::format("node attribute '{}' has no values", name));
    NodeAttribute out{name, static_cast<int>(a.components), {}};
    out.values.assign(a.values, a.values + v.node_count * a.components);
    for (std::size_t i = 0; i < out.values.size(); ++i)
      if (!std::isfinite(out.values[i]) || (name == "Cd" && (out.values[i] < 0.0f || out.values[i] > 4.0f)))
        throw malformed(fmt::format("node attribute '{}' has value {} at node {}{}", name, out.values[i],
                                    i / a.components,
                                    name == "Cd" ? " (expected finite, in [0, 4])" : " (expected finite)"));
    return out;
  }

  const growbench_plugin* t_;
  const AlgorithmInfo& info_;
  std::string who_;                                  // "algorithm 'NAME' (plugin PATH)", what its failures say
  mutable std::vector<std::string> checked_shapes_;  // organ shapes already found valid
  growbench_instance* inst_ = nullptr;
  const HostQueries* q_ = nullptr;
  std::uint64_t seed_ = 0;
  growbench_host host_{};
  growbench_scene scene_{};
  std::vector<growbench_mesh> meshes_;
  std::vector<growbench_seed> seeds_;
  std::vector<growbench_zone> zones_;
  mutable std::mutex fail_mutex_;
  mutable std::string failure_;
  mutable std::string host_error_;               // a failure of the host's own loop inside a plugin's call
  std::uint64_t version_ = 0;                    // bumped by every call that may change the plant
  mutable std::uint64_t plant_version_ = ~0ull;  // the version plant_ was copied at
  mutable Plant plant_;
  const Scene* scene_in_ = nullptr;
  mutable std::vector<std::vector<std::uint8_t>> decal_pixels_;  // per plant_.decals
  mutable std::vector<std::pair<int, int>> decal_sizes_;

  // The host table's functions: `context` is the PluginAlgorithm.
  static PluginAlgorithm& self(void* c) { return *static_cast<PluginAlgorithm*>(c); }
  friend struct HostFunctions;
};

// Each host function; all but fail() only read the algorithm's state, so they are safe from any thread.
struct HostFunctions {
  static void log(void* c, std::int32_t level, const char* message) {
    fmt::print(stderr, "{}: {}{}\n", self(c).info_.name, level == GROWBENCH_LOG_WARNING ? "warning: " : "",
               message ? message : "");
  }
  static void fail(void* c, const char* message) {
    PluginAlgorithm& a = self(c);
    std::lock_guard lock(a.fail_mutex_);
    if (a.failure_.empty()) a.failure_ = message ? message : "";
  }
  static std::int32_t cancelled(void* c) { return self(c).cancelled() ? 1 : 0; }
  // The trial's thread count limits TBB already (its global_control); halving to `grain` with the simple
  // partitioner makes the chunks a function of the range alone.
  // Nothing may throw into the plugin's C frames: a failure of the loop itself (memory for TBB's tasks) is kept
  // and raised by the host once the plugin's call returns.
  static void parallel_for(void* c, std::uint64_t begin, std::uint64_t end, std::uint64_t grain,
                           void (*body)(void*, std::uint64_t, std::uint64_t), void* user) {
    if (end <= begin || !body) return;
    const std::uint64_t g = grain > 0 ? grain : std::max<std::uint64_t>(1, (end - begin) / 64);
    try {
      tbb::parallel_for(
          tbb::blocked_range<std::uint64_t>(begin, end, g),
          [&](const tbb::blocked_range<std::uint64_t>& r) { body(user, r.begin(), r.end()); },
          tbb::simple_partitioner());
    } catch (const std::exception& e) {
      PluginAlgorithm& a = self(c);
      std::lock_guard lock(a.fail_mutex_);
      if (a.host_error_.empty()) a.host_error_ = fmt::format("the host's parallel_for failed: {}", e.what());
    }
  }
  static std::uint64_t random_bits(void* c, std::uint64_t stream, std::uint64_t counter) {
    return growbench::random_bits(self(c).seed_, stream, counter);
  }
  static void closest_points(void* c, const growbench_vec3* p, std::uint64_t n, float max_distance,
                             std::int32_t climbable_only, growbench_closest_hit* out) {
    std::vector<ClosestHit> hits(n);
    self(c).q_->closest_points(points(p, n), max_distance, climbable_only != 0, hits);
    abi::convert<ClosestHit>(hits, std::span(out, hits.size()));
  }
  static std::vector<Ray> rays_of(const growbench_ray* r, std::uint64_t n) {
    std::vector<Ray> v(n);
    abi::convert(std::span(r, v.size()), std::span(v));
    return v;
  }
  static void rays(void* c, const growbench_ray* r, std::uint64_t n, growbench_ray_hit* out) {
    std::vector<RayHit> hits(n);
    self(c).q_->rays(rays_of(r, n), hits);
    abi::convert<RayHit>(hits, std::span(out, hits.size()));
  }
  static void occluded(void* c, const growbench_ray* r, std::uint64_t n, std::uint8_t* out) {
    self(c).q_->occluded(rays_of(r, n), {out, static_cast<std::size_t>(n)});
  }
  static std::int32_t signed_distance(void* c, const growbench_vec3* p, std::uint64_t n, float* distance,
                                      growbench_vec3* gradient) {
    const HostQueries& q = *self(c).q_;
    if (!q.has_sdf()) return GROWBENCH_ERROR;
    q.signed_distance(
        points(p, n), distance ? std::span<float>(distance, static_cast<std::size_t>(n)) : std::span<float>(),
        gradient ? std::span<glm::vec3>(reinterpret_cast<glm::vec3*>(gradient), static_cast<std::size_t>(n))
                 : std::span<glm::vec3>());
    return GROWBENCH_OK;
  }
  static void inside(void* c, const growbench_vec3* p, std::uint64_t n, std::uint8_t* out) {
    self(c).q_->inside(points(p, n), {out, static_cast<std::size_t>(n)});
  }
  static void inside_shape(void* c, std::int32_t shape, const growbench_vec3* p, std::uint64_t n, std::uint8_t* out) {
    self(c).q_->inside_shape(shape, points(p, n), {out, static_cast<std::size_t>(n)});
  }
  static void sample_surface(void* c, std::uint64_t seed, std::uint64_t first, std::uint64_t n,
                             growbench_surface_sample* out) {
    std::vector<SurfaceSample> s(n);
    self(c).q_->sample_surface(seed, first, s);
    abi::convert<SurfaceSample>(s, std::span(out, s.size()));
  }
  static void light_visible(void* c, const growbench_vec3* p, std::uint64_t n, float bias, std::uint8_t* out) {
    self(c).q_->light_visible(points(p, n), bias, {out, static_cast<std::size_t>(n)});
  }
  static std::int32_t mesh_uvs(void* c, std::uint32_t mesh, const float** uvs, std::uint64_t* count,
                               const std::uint32_t** triangles) {
    const auto& meshes = self(c).scene_in_->meshes;
    const bool has = mesh < meshes.size() && meshes[mesh].has_uvs();
    static_assert(sizeof(glm::vec2) == 2 * sizeof(float) && sizeof(glm::uvec3) == 3 * sizeof(std::uint32_t));
    if (uvs) *uvs = has ? &meshes[mesh].uvs[0].x : nullptr;
    if (count) *count = has ? meshes[mesh].uvs.size() : 0;
    if (triangles) *triangles = has ? &meshes[mesh].uv_triangles[0].x : nullptr;
    return has ? 1 : 0;
  }
  static void surface_frames(void* c, const growbench_surface_point* p, std::uint64_t n, growbench_surface_frame* out) {
    const auto& meshes = self(c).scene_in_->meshes;
    for (std::uint64_t i = 0; i < n; ++i) {
      const glm::vec3 x = abi::of(p[i].point);
      const bool ok = p[i].mesh < meshes.size() && meshes[p[i].mesh].has_uvs() &&
                      p[i].triangle < meshes[p[i].mesh].triangles.size() && std::isfinite(x.x + x.y + x.z);
      out[i] = ok ? surface_frame(meshes[p[i].mesh], p[i].triangle, x) : growbench_surface_frame{};
    }
  }
  static PluginAlgorithm& self(void* c) { return PluginAlgorithm::self(c); }
};

void PluginAlgorithm::make_host() {
  host_ = {};
  // A plugin of an older version is given the table a host of its version gave: that version, and its size.
  const std::uint32_t v = std::min(t_->abi_version, GROWBENCH_PLUGIN_ABI_VERSION);
  host_.abi_version = v;
  host_.struct_size = v < 2   ? offsetof(growbench_host, parallel_for)
                      : v < 3 ? offsetof(growbench_host, mesh_uvs)
                              : sizeof(growbench_host);
  host_.context = this;
  host_.threads =
      static_cast<std::uint32_t>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  host_.log = &HostFunctions::log;
  host_.fail = &HostFunctions::fail;
  host_.cancelled = &HostFunctions::cancelled;
  host_.random_bits = &HostFunctions::random_bits;
  host_.closest_points = &HostFunctions::closest_points;
  host_.rays = &HostFunctions::rays;
  host_.occluded = &HostFunctions::occluded;
  host_.signed_distance = &HostFunctions::signed_distance;
  host_.inside = &HostFunctions::inside;
  host_.inside_shape = &HostFunctions::inside_shape;
  host_.sample_surface = &HostFunctions::sample_surface;
  host_.light_visible = &HostFunctions::light_visible;
  if (v >= 2) host_.parallel_for = &HostFunctions::parallel_for;
  if (v >= 3) {
    host_.mesh_uvs = &HostFunctions::mesh_uvs;
    host_.surface_frames = &HostFunctions::surface_frames;
  }
}

}  // namespace

std::unique_ptr<GrowthAlgorithm> make_plugin_algorithm(const growbench_plugin* table, const AlgorithmInfo& info,
                                                       const std::string& path) {
  return std::make_unique<PluginAlgorithm>(table, info, path);
}

}  // namespace growbench
