// A built-in algorithm exported as a plugin, from its unchanged source: the scene arrives through the
// C ABI and is rebuilt as a Scene, the parameters as Params, and every query crosses to the host's
// table. growbench_builtin_plugin() (algorithms/plugins/CMakeLists.txt) compiles it with
// GROWBENCH_BUILTIN, the algorithm's registration name, and GROWBENCH_PLUGIN_NAME, the name it takes.
// It proves the boundary: the plugin must grow the built-in's plant bit for bit.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "algorithms/algorithm.hpp"
#include "algorithms/plugins/abi_convert.hpp"
#include "growbench/plugin.hpp"

#define GROWBENCH_CONCAT2(a, b) a##b
#define GROWBENCH_CONCAT(a, b) GROWBENCH_CONCAT2(a, b)
#define GROWBENCH_ENTRY_OF_BUILTIN GROWBENCH_CONCAT(algorithm_entry_, GROWBENCH_BUILTIN)

namespace growbench {

AlgorithmEntry GROWBENCH_ENTRY_OF_BUILTIN();

namespace {

namespace sdk = growbench::sdk;

const AlgorithmEntry& builtin() {
  static const AlgorithmEntry e = GROWBENCH_ENTRY_OF_BUILTIN();
  return e;
}

TriangleMesh mesh_of(const growbench_mesh& m) {
  TriangleMesh t;
  t.name = m.name ? m.name : "";
  for (std::uint64_t i = 0; i < m.vertex_count; ++i) t.vertices.push_back(abi::of(m.vertices[i]));
  for (std::uint64_t i = 0; i < m.triangle_count; ++i)
    t.triangles.emplace_back(m.triangles[3 * i], m.triangles[3 * i + 1], m.triangles[3 * i + 2]);
  t.climbable = m.climbable != 0;
  return t;
}

Shape shape_of(const growbench_shape& s) {
  Shape r;
  r.kind = s.kind == GROWBENCH_SHAPE_BOX         ? Shape::Kind::Box
           : s.kind == GROWBENCH_SHAPE_ELLIPSOID ? Shape::Kind::Sphere
                                                 : Shape::Kind::Mesh;
  r.min = abi::of(s.min);
  r.max = abi::of(s.max);
  r.center = abi::of(s.center);
  r.radii = abi::of(s.radii);
  if (r.kind == Shape::Kind::Mesh) r.mesh = mesh_of(s.mesh);
  return r;
}

Scene scene_of(const growbench_scene& s) {
  Scene r;
  r.name = s.name ? s.name : "";
  for (std::uint32_t i = 0; i < s.mesh_count; ++i) r.meshes.push_back(mesh_of(s.meshes[i]));
  for (std::uint32_t i = 0; i < s.seed_count; ++i)
    r.seeds.push_back({abi::of(s.seeds[i].position), abi::of(s.seeds[i].direction), s.seeds[i].start_step});
  r.light.kind = s.light.point ? Light::Kind::Point : Light::Kind::Sun;
  r.light.direction = abi::of(s.light.direction);
  r.light.position = abi::of(s.light.position);
  if (s.has_envelope) r.envelope = shape_of(s.envelope);
  for (std::uint32_t i = 0; i < s.zone_count; ++i)
    r.zones.push_back({static_cast<Zone::Kind>(s.zones[i].kind), shape_of(s.zones[i].shape), s.zones[i].strength});
  return r;
}

// The queries, answered by the host through its C table.
class TableQueries final : public HostQueries {
 public:
  explicit TableQueries(const growbench_host& h, bool has_sdf) : h_(h), has_sdf_(has_sdf) {}
  bool has_sdf() const override { return has_sdf_; }
  void closest_points(std::span<const glm::vec3> p, float max_distance, bool climbable_only,
                      std::span<ClosestHit> out) const override {
    std::vector<growbench_closest_hit> hits(p.size());
    h_.closest_points(h_.context, abi::of(p.data()), p.size(), max_distance, climbable_only ? 1 : 0, hits.data());
    abi::convert<growbench_closest_hit>(hits, out);
  }
  static std::vector<growbench_ray> abi_rays(std::span<const Ray> r) {
    std::vector<growbench_ray> v(r.size());
    abi::convert(r, std::span(v));
    return v;
  }
  void rays(std::span<const Ray> r, std::span<RayHit> out) const override {
    const auto rays = abi_rays(r);
    std::vector<growbench_ray_hit> hits(r.size());
    h_.rays(h_.context, rays.data(), rays.size(), hits.data());
    abi::convert<growbench_ray_hit>(hits, out);
  }
  void occluded(std::span<const Ray> r, std::span<std::uint8_t> out) const override {
    const auto rays = abi_rays(r);
    h_.occluded(h_.context, rays.data(), rays.size(), out.data());
  }
  void signed_distance(std::span<const glm::vec3> p, std::span<float> distance,
                       std::span<glm::vec3> gradient) const override {
    auto* g = gradient.empty() ? nullptr : reinterpret_cast<growbench_vec3*>(gradient.data());
    float* d = distance.empty() ? nullptr : distance.data();
    if (h_.signed_distance(h_.context, abi::of(p.data()), p.size(), d, g) != GROWBENCH_OK)
      throw InputError("the scene has no distance field");
  }
  void inside(std::span<const glm::vec3> p, std::span<std::uint8_t> out) const override {
    h_.inside(h_.context, abi::of(p.data()), p.size(), out.data());
  }
  void inside_shape(int shape, std::span<const glm::vec3> p, std::span<std::uint8_t> out) const override {
    h_.inside_shape(h_.context, shape, abi::of(p.data()), p.size(), out.data());
  }
  void sample_surface(std::uint64_t seed, std::uint64_t first, std::span<SurfaceSample> out) const override {
    std::vector<growbench_surface_sample> s(out.size());
    h_.sample_surface(h_.context, seed, first, out.size(), s.data());
    abi::convert<growbench_surface_sample>(s, out);
  }
  void light_visible(std::span<const glm::vec3> p, float bias, std::span<std::uint8_t> out) const override {
    h_.light_visible(h_.context, abi::of(p.data()), p.size(), bias, out.data());
  }

 private:
  const growbench_host& h_;
  bool has_sdf_;
};

sdk::Param row_of(const ParamSpec& s) {
  auto ranged = [&](sdk::Param p) { return std::move(p).range(s.min, s.max).unit(s.unit).doc(s.doc); };
  switch (s.type) {
    case ParamType::Int:
      return ranged(sdk::integer(s.name, std::get<std::int64_t>(s.default_value)));
    case ParamType::Real:
      return ranged(sdk::real(s.name, std::get<double>(s.default_value)));
    case ParamType::Vec3: {
      const glm::dvec3 d = std::get<glm::dvec3>(s.default_value);
      return ranged(sdk::vector3(s.name, d.x, d.y, d.z));
    }
    case ParamType::Bool:
      return sdk::boolean(s.name, std::get<bool>(s.default_value)).unit(s.unit).doc(s.doc);
    case ParamType::String:
      return sdk::text(s.name, std::get<std::string>(s.default_value)).unit(s.unit).doc(s.doc);
    case ParamType::Choice:
      return sdk::choice(s.name, std::get<std::string>(s.default_value), s.choices).unit(s.unit).doc(s.doc);
  }
  throw std::logic_error("unknown parameter type");
}

// The parameter values as the built-in reads them: each set through the table, exactly as given.
Params params_of(const AlgorithmInfo& info, const sdk::Params& given) {
  Params p(fmt::format("algorithm '{}'", GROWBENCH_PLUGIN_NAME), info.params);
  for (const ParamSpec& s : info.params) {
    switch (s.type) {
      case ParamType::Int:
        p.set_json(s.name, given.integer(s.name));
        break;
      case ParamType::Real:
        p.set_json(s.name, given.real(s.name));
        break;
      case ParamType::Bool:
        p.set_json(s.name, given.boolean(s.name));
        break;
      case ParamType::String:
      case ParamType::Choice:
        p.set_json(s.name, given.text(s.name));
        break;
      case ParamType::Vec3:
        p.set_json(s.name, given.vector3(s.name));
        break;
    }
  }
  return p;
}

class Builtin final : public sdk::Algorithm {
 public:
  static sdk::Info info() {
    const AlgorithmInfo& i = builtin().info();
    std::vector<sdk::Param> rows;
    for (const ParamSpec& s : i.params) rows.push_back(row_of(s));
    return {GROWBENCH_PLUGIN_NAME, i.summary + " (the built-in, as a plugin)", "builtin", std::move(rows),
            i.test_params};
  }

  void start(const sdk::Context& c) override {
    auto a = builtin().make();
    auto* portable = dynamic_cast<PortableGrowthAlgorithm*>(a.get());
    if (!portable) throw std::logic_error("the built-in does not implement PortableGrowthAlgorithm");
    a.release();
    algo_.reset(portable);
    scene_ = scene_of(c.scene);
    queries_ = std::make_unique<TableQueries>(c.host.table(), c.scene.has_sdf != 0);
    algo_->start_with(scene_, *queries_, params_of(builtin().info(), c.params), c.seed);
  }
  bool step() override { return algo_->step(); }
  void finish() override { algo_->finish(); }
  std::vector<std::pair<std::string, double>> stats() const override { return algo_->stats(); }
  std::pair<std::uint64_t, std::uint64_t> counts() override { return {algo_->node_count(), algo_->organ_count()}; }
  const sdk::Plant& current_plant() override {
    const Plant& p = algo_->plant();
    plant.nodes.clear();
    plant.organs.clear();
    plant.polygon_vertices.clear();
    plant.polygon_offsets.clear();
    for (const auto& n : p.nodes)
      plant.add_node(abi::of(n.position), n.radius, n.parent, n.order, n.shoot, n.birth_step);
    for (const auto& o : p.organs)
      plant.organs.push_back({abi::of(o.position),
                              {o.orientation.w, o.orientation.x, o.orientation.y, o.orientation.z},
                              o.size,
                              static_cast<std::int32_t>(o.kind),
                              o.node,
                              {o.stamp[0], o.stamp[1], o.stamp[2]}});
    for (const auto& poly : p.polygons) {
      if (plant.polygon_offsets.empty()) plant.polygon_offsets.push_back(0);
      for (const auto& v : poly.vertices) plant.polygon_vertices.push_back(abi::of(v));
      plant.polygon_offsets.push_back(plant.polygon_vertices.size());
    }
    return plant;
  }

 private:
  Scene scene_;
  std::unique_ptr<TableQueries> queries_;
  std::unique_ptr<PortableGrowthAlgorithm> algo_;
};

}  // namespace
}  // namespace growbench

GROWBENCH_PLUGIN(growbench::Builtin)
