#include "harness/record/record.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <type_traits>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/params.hpp"
#include "harness/record/files.hpp"

namespace growbench {
using nlohmann::json;

namespace {

// ---------------------------------------------------------------- reading

// A JSON value and where it is: the file (for errors) and the path to it ("trials[3].samples[0]").
struct Node {
  const json& j;
  const std::string& source;
  std::string path;

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}: at {}: {}", source, path.empty() ? "the top level" : path, what));
  }
  [[nodiscard]] Node key(std::string_view k) const {
    return {j.at(std::string(k)), source, path.empty() ? std::string(k) : fmt::format("{}.{}", path, k)};
  }
  [[nodiscard]] Node index(std::size_t i) const { return {j[i], source, fmt::format("{}[{}]", path, i)}; }
  [[nodiscard]] std::string got() const {
    return fmt::format("got {}", j.is_string() ? j.dump() : std::string(j.type_name()));
  }
};

void read(const Node& n, double& v) {
  if (!n.j.is_number()) n.fail("expected a number, " + n.got());
  v = n.j.get<double>();
}

// Integers: JSON integers, and whole numbers written as floats (1e6 from Python), in range.
template <class T>
requires std::is_integral_v<T>
void read(const Node& n, T& v) {
  const char* what = std::is_signed_v<T> ? "an integer" : "a non-negative integer";
  if (n.j.is_number_unsigned()) {
    const auto u = n.j.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(std::numeric_limits<T>::max()))
      n.fail(fmt::format("expected {}, {} is too large", what, u));
    v = static_cast<T>(u);
  } else if (n.j.is_number_integer()) {
    const auto s = n.j.get<std::int64_t>();
    if ((std::is_unsigned_v<T> && s < 0) ||
        (std::is_signed_v<T> && (s < static_cast<std::int64_t>(std::numeric_limits<T>::min()) ||
                                 s > static_cast<std::int64_t>(std::numeric_limits<T>::max()))))
      n.fail(fmt::format("expected {}, got {}", what, s));
    v = static_cast<T>(s);
  } else if (n.j.is_number_float()) {
    const double d = n.j.get<double>();
    if (d != std::floor(d) || d < static_cast<double>(std::numeric_limits<T>::min()) ||
        d >= std::ldexp(1.0, std::numeric_limits<T>::digits))
      n.fail(fmt::format("expected {}, got {}", what, n.j.dump()));
    v = static_cast<T>(d);
  } else {
    n.fail(fmt::format("expected {}, {}", what, n.got()));
  }
}

void read(const Node& n, bool& v) {
  if (!n.j.is_boolean()) n.fail("expected true or false, " + n.got());
  v = n.j.get<bool>();
}

void read(const Node& n, std::string& v) {
  if (!n.j.is_string()) n.fail("expected a string, " + n.got());
  v = n.j.get<std::string>();
}

// Open-ended parts (metrics and parameters by name, sweep values, versions): objects, kept as they are.
void read(const Node& n, json& v) {
  if (!n.j.is_object()) n.fail("expected an object, " + n.got());
  v = n.j;
}

template <class T>
void read(const Node& n, std::vector<T>& v);
template <class T>
void read(const Node& n, std::map<std::string, T>& v);
template <class T, std::size_t N>
void read(const Node& n, std::array<T, N>& v);

// The fields of one object: each named field is read if present, and done() refuses the ones nobody named.
class Fields {
 public:
  explicit Fields(const Node& n) : n_(n) {
    if (!n.j.is_object()) n.fail("expected an object, " + n.got());
  }
  // Absent: `v` keeps its default.
  template <class T>
  void field(std::string_view key, T& v) {
    named_.emplace_back(key);
    if (const auto it = n_.j.find(std::string(key)); it != n_.j.end()) read(n_.key(key), v);
  }
  // Absent (or null): empty.
  template <class T>
  void field(std::string_view key, std::optional<T>& v) {
    named_.emplace_back(key);
    v.reset();
    const auto it = n_.j.find(std::string(key));
    if (it == n_.j.end() || it->is_null()) return;
    read(n_.key(key), v.emplace());
  }
  // Absent: an error.
  template <class T>
  void required(std::string_view key, T& v) {
    if (!n_.j.contains(std::string(key))) n_.fail(fmt::format("expected the field '{}'", key));
    field(key, v);
  }
  void done() const {
    for (const auto& [k, v] : n_.j.items()) {
      if (std::find(named_.begin(), named_.end(), k) != named_.end()) continue;
      const std::string near = closest_match(k, named_);
      n_.key(k).fail(
          fmt::format("unknown field '{}'{}", k, near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near)));
    }
  }
  [[nodiscard]] const Node& node() const { return n_; }

 private:
  const Node& n_;
  std::vector<std::string> named_;
};

template <class T>
void read(const Node& n, std::vector<T>& v) {
  if (!n.j.is_array()) n.fail("expected an array, " + n.got());
  v.assign(n.j.size(), T{});
  for (std::size_t i = 0; i < v.size(); ++i) read(n.index(i), v[i]);
}

template <class T>
void read(const Node& n, std::map<std::string, T>& v) {
  if (!n.j.is_object()) n.fail("expected an object, " + n.got());
  v.clear();
  for (const auto& [k, x] : n.j.items()) read(n.key(k), v[k]);
}

template <class T, std::size_t N>
void read(const Node& n, std::array<T, N>& v) {
  if (!n.j.is_array()) n.fail(fmt::format("expected an array of {}, {}", N, n.got()));
  if (n.j.size() != N) n.fail(fmt::format("expected an array of {}, got {} items", N, n.j.size()));
  for (std::size_t i = 0; i < N; ++i) read(n.index(i), v[i]);
}

// ---------------------------------------------------------------- writing

template <class T>
json to_json_value(const T& v) {
  if constexpr (requires { to_json(v); })
    return to_json(v);
  else
    return json(v);
}

template <class T>
json to_json_value(const std::vector<T>& v) {
  json a = json::array();
  for (const auto& x : v) a.push_back(to_json_value(x));
  return a;
}

template <class T>
json to_json_value(const std::map<std::string, T>& v) {
  json o = json::object();
  for (const auto& [k, x] : v) o[k] = to_json_value(x);
  return o;
}

// Optional members are written only when present.
template <class T>
void put(json& j, const char* key, const std::optional<T>& v) {
  if (v) j[key] = to_json_value(*v);
}

template <class T>
void put(json& j, const char* key, const T& v) {
  j[key] = to_json_value(v);
}

// Nullable members are always written, as null when empty.
template <class T>
void put_nullable(json& j, const char* key, const std::optional<T>& v) {
  j[key] = v ? json(*v) : json(nullptr);
}

}  // namespace

// ---------------------------------------------------------------- the structs, each written and read once

const PhaseMeasures* Phases::find(std::string_view name) const {
  return const_cast<Phases*>(this)->find(name);
}

PhaseMeasures* Phases::find(std::string_view name) {
  std::optional<PhaseMeasures>* p = name == "scene_load"    ? &scene_load
                                    : name == "query_build" ? &query_build
                                    : name == "growth"      ? &growth
                                    : name == "organs"      ? &organs
                                    : name == "meshing"     ? &meshing
                                    : name == "export"      ? &exporting
                                    : name == "metrics"     ? &metrics
                                                            : nullptr;
  return p && *p ? &**p : nullptr;
}

json to_json(const PhaseMeasures& v) {
  json j = {{"wall_s", v.wall_s},
            {"cpu_s", v.cpu_s},
            {"peak_rss_bytes", v.peak_rss_bytes},
            {"peak_rss_reset", v.peak_rss_reset},
            {"alloc_count", v.alloc_count},
            {"alloc_bytes", v.alloc_bytes}};
  put(j, "bvh_s", v.bvh_s);
  put(j, "sdf_s", v.sdf_s);
  put(j, "sdf_active_voxels", v.sdf_active_voxels);
  put(j, "voxel_size_m", v.voxel_size_m);
  put(j, "frame_capture_wall_s", v.frame_capture_wall_s);
  put(j, "frame_capture_cpu_s", v.frame_capture_cpu_s);
  return j;
}
void read(const Node& n, PhaseMeasures& v) {
  Fields f(n);
  f.field("wall_s", v.wall_s);
  f.field("cpu_s", v.cpu_s);
  f.field("peak_rss_bytes", v.peak_rss_bytes);
  f.field("peak_rss_reset", v.peak_rss_reset);
  f.field("alloc_count", v.alloc_count);
  f.field("alloc_bytes", v.alloc_bytes);
  f.field("bvh_s", v.bvh_s);
  f.field("sdf_s", v.sdf_s);
  f.field("sdf_active_voxels", v.sdf_active_voxels);
  f.field("voxel_size_m", v.voxel_size_m);
  f.field("frame_capture_wall_s", v.frame_capture_wall_s);
  f.field("frame_capture_cpu_s", v.frame_capture_cpu_s);
  f.done();
}

json to_json(const Phases& v) {
  json j = json::object();
  v.each([&](std::string_view name, const PhaseMeasures& p) { j[std::string(name)] = to_json(p); });
  return j;
}
void read(const Node& n, Phases& v) {
  Fields f(n);
  f.field("scene_load", v.scene_load);
  f.field("query_build", v.query_build);
  f.field("growth", v.growth);
  f.field("organs", v.organs);
  f.field("meshing", v.meshing);
  f.field("export", v.exporting);
  f.field("metrics", v.metrics);
  f.done();
}

json to_json(const Counts& v) {
  return {{"nodes", v.nodes},
          {"segments", v.segments},
          {"leaves", v.leaves},
          {"organs", v.organs},
          {"polygons", v.polygons},
          {"mesh_vertices", v.mesh_vertices},
          {"mesh_triangles", v.mesh_triangles}};
}
void read(const Node& n, Counts& v) {
  Fields f(n);
  f.field("nodes", v.nodes);
  f.field("segments", v.segments);
  f.field("leaves", v.leaves);
  f.field("organs", v.organs);
  f.field("polygons", v.polygons);
  f.field("mesh_vertices", v.mesh_vertices);
  f.field("mesh_triangles", v.mesh_triangles);
  f.done();
}

json to_json(const OutputBytes& v) {
  json j = json::object();
  put(j, "obj", v.obj);
  put(j, "ply", v.ply);
  put(j, "glb", v.glb);
  put(j, "glb_plain", v.glb_plain);
  put(j, "skeleton_obj", v.skeleton_obj);
  put(j, "skeleton_ply", v.skeleton_ply);
  if (!v.algorithm_files.empty()) put(j, "algorithm_files", v.algorithm_files);
  return j;
}
void read(const Node& n, OutputBytes& v) {
  Fields f(n);
  f.field("obj", v.obj);
  f.field("ply", v.ply);
  f.field("glb", v.glb);
  f.field("glb_plain", v.glb_plain);
  f.field("skeleton_obj", v.skeleton_obj);
  f.field("skeleton_ply", v.skeleton_ply);
  f.field("algorithm_files", v.algorithm_files);
  f.done();
}

json to_json(const Curve& v) {
  return {{"every", v.every}, {"step", v.step}, {"nodes", v.nodes}, {"organs", v.organs}, {"wall_s", v.wall_s}};
}
void read(const Node& n, Curve& v) {
  Fields f(n);
  f.field("every", v.every);
  f.field("step", v.step);
  f.field("nodes", v.nodes);
  f.field("organs", v.organs);
  f.field("wall_s", v.wall_s);
  f.done();
}

json to_json(const SceneInfo& v) {
  return {{"spec", v.spec},           {"name", v.name},   {"hash", v.hash},
          {"triangles", v.triangles}, {"seeds", v.seeds}, {"params", v.params}};
}
void read(const Node& n, SceneInfo& v) {
  Fields f(n);
  f.field("spec", v.spec);
  f.field("name", v.name);
  f.field("hash", v.hash);
  f.field("triangles", v.triangles);
  f.field("seeds", v.seeds);
  f.field("params", v.params);
  f.done();
}

json to_json(const FramesInfo& v) {
  return {{"every", v.every}, {"count", v.count}, {"dir", v.dir}};
}
void read(const Node& n, FramesInfo& v) {
  Fields f(n);
  f.field("every", v.every);
  f.field("count", v.count);
  f.field("dir", v.dir);
  f.done();
}

json to_json(const OrganPassRecord& v) {
  return {{"options", v.options}, {"placed", v.placed}, {"fallen_back", v.fallen_back}, {"dropped", v.dropped}};
}
void read(const Node& n, OrganPassRecord& v) {
  Fields f(n);
  f.field("options", v.options);
  f.field("placed", v.placed);
  f.field("fallen_back", v.fallen_back);
  f.field("dropped", v.dropped);
  f.done();
}

json to_json(const PluginOrigin& v) {
  return {{"name", v.name}, {"path", v.path}, {"hash", v.hash}, {"abi_version", v.abi_version}, {"version", v.version}};
}
void read(const Node& n, PluginOrigin& v) {
  Fields f(n);
  f.required("name", v.name);
  f.required("path", v.path);
  f.required("hash", v.hash);
  f.required("abi_version", v.abi_version);
  f.field("version", v.version);
  f.done();
}

json to_json(const RunContext& v) {
  json j = {{"growbench_commit", v.growbench_commit},
            {"dirty", v.dirty},
            {"configured_commit", v.configured_commit},
            {"build_type", v.build_type},
            {"compiler", v.compiler},
            {"cxx_flags", v.cxx_flags},
            {"binary_hash", v.binary_hash},
            {"cpu_model", v.cpu_model},
            {"hardware_threads", v.hardware_threads},
            {"date", v.date},
            {"alloc_counting", v.alloc_counting},
            {"dependencies", v.dependencies}};
  put_nullable(j, "commit_time", v.commit_time);
  put(j, "suite_file_hash", v.suite_file_hash);
  put(j, "parent_threads_at_fork", v.parent_threads_at_fork);
  put(j, "mixed_machines", v.mixed_machines);
  if (!v.plugins.empty()) {
    json list = json::array();
    for (const auto& p : v.plugins) list.push_back(to_json(p));
    j["plugins"] = std::move(list);
  }
  return j;
}
void read(const Node& n, RunContext& v) {
  Fields f(n);
  f.field("growbench_commit", v.growbench_commit);
  f.field("dirty", v.dirty);
  f.field("commit_time", v.commit_time);
  f.field("configured_commit", v.configured_commit);
  f.field("build_type", v.build_type);
  f.field("compiler", v.compiler);
  f.field("cxx_flags", v.cxx_flags);
  f.field("binary_hash", v.binary_hash);
  f.field("cpu_model", v.cpu_model);
  f.field("hardware_threads", v.hardware_threads);
  f.field("date", v.date);
  f.field("alloc_counting", v.alloc_counting);
  f.field("dependencies", v.dependencies);
  f.field("suite_file_hash", v.suite_file_hash);
  f.field("parent_threads_at_fork", v.parent_threads_at_fork);
  f.field("mixed_machines", v.mixed_machines);
  f.field("plugins", v.plugins);
  f.done();
}

json to_json(const RenderRecord& v) {
  json j = {{"status", v.status},     {"warnings", v.warnings}, {"png", v.png},       {"pov", v.pov},
            {"log", v.log},           {"width", v.width},       {"height", v.height}, {"pov_bytes", v.pov_bytes},
            {"write_s", v.write_s},   {"wall_s", v.wall_s},     {"cpu_s", v.cpu_s},   {"quality", v.quality},
            {"branches", v.branches}, {"threads", v.threads}};
  put(j, "message", v.message);
  put(j, "camera", v.camera);
  put(j, "scene_extent", v.scene_extent);
  put(j, "backdrop", v.backdrop);
  put(j, "dof", v.dof);
  return j;
}
void read(const Node& n, RenderRecord& v) {
  Fields f(n);
  f.field("status", v.status);
  f.field("message", v.message);
  f.field("warnings", v.warnings);
  f.field("png", v.png);
  f.field("pov", v.pov);
  f.field("log", v.log);
  f.field("width", v.width);
  f.field("height", v.height);
  f.field("pov_bytes", v.pov_bytes);
  f.field("write_s", v.write_s);
  f.field("wall_s", v.wall_s);
  f.field("cpu_s", v.cpu_s);
  f.field("quality", v.quality);
  f.field("branches", v.branches);
  f.field("threads", v.threads);
  f.field("camera", v.camera);
  f.field("scene_extent", v.scene_extent);
  f.field("backdrop", v.backdrop);
  f.field("dof", v.dof);
  f.done();
}

json to_json(const AnimationRecord& v) {
  json j = {{"status", v.status}, {"frames", v.frames}};
  put(j, "frame_pattern", v.frame_pattern);
  put(j, "message", v.message);
  put(j, "file", v.file);
  put(j, "bytes", v.bytes);
  return j;
}
void read(const Node& n, AnimationRecord& v) {
  Fields f(n);
  f.field("status", v.status);
  f.field("frames", v.frames);
  f.field("frame_pattern", v.frame_pattern);
  f.field("message", v.message);
  f.field("file", v.file);
  f.field("bytes", v.bytes);
  f.done();
}

json to_json(const TrialRecord& v) {
  json j = {{"schema_version", v.schema_version},
            {"status", v.status},
            {"algorithm", v.algorithm},
            {"seed", v.seed},
            {"threads", v.threads},
            {"max_steps", v.max_steps},
            {"phases", to_json(v.phases)},
            {"scene", to_json(v.scene)},
            {"params", v.params},
            {"steps", v.steps},
            {"stopped_by", v.stopped_by},
            {"curve", to_json(v.curve)},
            {"counts", to_json(v.counts)},
            {"total_length_m", v.total_length_m},
            {"output_bytes", to_json(v.output_bytes)},
            {"geometry_hash", v.geometry_hash},
            {"algorithm_stats", to_json_value(v.algorithm_stats)},
            {"peak_rss_bytes", v.peak_rss_bytes}};
  put(j, "leaf_obj", v.leaf_obj);
  put(j, "organs", v.organs);
  put(j, "frames", v.frames);
  put(j, "snapshot_bytes", v.snapshot_bytes);
  put(j, "metrics", v.metrics);
  put(j, "context", v.context);
  put(j, "render", v.render);
  put(j, "animation", v.animation);
  put(j, "turntable", v.turntable);
  return j;
}
void read(const Node& n, TrialRecord& v) {
  Fields f(n);
  f.field("schema_version", v.schema_version);
  f.field("status", v.status);
  f.field("algorithm", v.algorithm);
  f.field("seed", v.seed);
  f.field("threads", v.threads);
  f.field("max_steps", v.max_steps);
  f.field("phases", v.phases);
  f.field("scene", v.scene);
  f.field("params", v.params);
  f.field("leaf_obj", v.leaf_obj);
  f.field("organs", v.organs);
  f.field("frames", v.frames);
  f.field("steps", v.steps);
  f.field("stopped_by", v.stopped_by);
  f.field("curve", v.curve);
  f.field("snapshot_bytes", v.snapshot_bytes);
  f.field("metrics", v.metrics);
  f.field("counts", v.counts);
  f.field("total_length_m", v.total_length_m);
  f.field("output_bytes", v.output_bytes);
  f.field("geometry_hash", v.geometry_hash);
  f.field("algorithm_stats", v.algorithm_stats);
  f.field("peak_rss_bytes", v.peak_rss_bytes);
  f.field("context", v.context);
  f.field("render", v.render);
  f.field("animation", v.animation);
  f.field("turntable", v.turntable);
  f.done();
}

json to_json(const TrialSpecRecord& v) {
  json seeds = json::array();
  for (const auto& p : v.seed_at) seeds.push_back({p[0], p[1], p[2]});
  json j = {{"algorithm", v.algorithm},
            {"scene", v.scene},
            {"scene_params", v.scene_params},
            {"params", v.params},
            {"seed", v.seed},
            {"seed_at", seeds},
            {"max_steps", v.max_steps},
            {"time_limit_s", v.time_limit_s},
            {"threads", v.threads},
            {"voxel_size", v.voxel_size},
            {"sides", v.sides},
            {"budget_nodes", v.budget_nodes},
            {"budget_length_m", v.budget_length_m},
            {"metrics", v.metrics},
            {"frame_every", v.frame_every},
            {"fault", v.fault}};
  put(j, "leaf_obj", v.leaf_obj);
  put(j, "organs", v.organs);
  put(j, "glb", v.glb);
  put(j, "out_dir", v.out_dir);
  put(j, "context", v.context);
  put(j, "skip_teardown", v.skip_teardown);
  put(j, "plugins", v.plugins);
  return j;
}
void read(const Node& n, TrialSpecRecord& v) {
  Fields f(n);
  f.required("algorithm", v.algorithm);
  f.required("scene", v.scene);
  f.field("scene_params", v.scene_params);
  f.field("params", v.params);
  f.field("seed", v.seed);
  f.field("seed_at", v.seed_at);
  f.field("max_steps", v.max_steps);
  f.field("time_limit_s", v.time_limit_s);
  f.field("threads", v.threads);
  f.field("voxel_size", v.voxel_size);
  f.field("sides", v.sides);
  f.field("budget_nodes", v.budget_nodes);
  f.field("budget_length_m", v.budget_length_m);
  f.field("metrics", v.metrics);
  f.field("frame_every", v.frame_every);
  f.field("fault", v.fault);
  f.field("leaf_obj", v.leaf_obj);
  f.field("organs", v.organs);
  f.field("glb", v.glb);
  f.field("out_dir", v.out_dir);
  f.field("context", v.context);
  f.field("skip_teardown", v.skip_teardown);
  f.field("plugins", v.plugins);
  f.done();
}

json to_json(const AllocCount& v) {
  return {{"count", v.count}, {"bytes", v.bytes}};
}
void read(const Node& n, AllocCount& v) {
  Fields f(n);
  f.field("count", v.count);
  f.field("bytes", v.bytes);
  f.done();
}

json to_json(const SuiteSample& v) {
  json j = {{"repetition", v.repetition},         {"status", v.status},
            {"child_wall_s", v.child_wall_s},     {"child_user_s", v.child_user_s},
            {"child_system_s", v.child_system_s}, {"child_max_rss_bytes", v.child_max_rss_bytes}};
  put(j, "message", v.message);
  put(j, "phases", v.phases);
  put(j, "steps", v.steps);
  put(j, "instructions", v.instructions);
  put(j, "outside_phases_s", v.outside_phases_s);
  put(j, "launch_s", v.launch_s);
  put(j, "launch_fork_s", v.launch_fork_s);
  put(j, "child_bookkeeping_s", v.child_bookkeeping_s);
  put(j, "teardown_s", v.teardown_s);
  put(j, "parent_s", v.parent_s);
  put(j, "harness_overhead_s", v.harness_overhead_s);
  return j;
}
void read(const Node& n, SuiteSample& v) {
  Fields f(n);
  f.field("repetition", v.repetition);
  f.field("status", v.status);
  f.field("message", v.message);
  f.field("child_wall_s", v.child_wall_s);
  f.field("child_user_s", v.child_user_s);
  f.field("child_system_s", v.child_system_s);
  f.field("child_max_rss_bytes", v.child_max_rss_bytes);
  f.field("phases", v.phases);
  f.field("steps", v.steps);
  f.field("instructions", v.instructions);
  f.field("outside_phases_s", v.outside_phases_s);
  f.field("launch_s", v.launch_s);
  f.field("launch_fork_s", v.launch_fork_s);
  f.field("child_bookkeeping_s", v.child_bookkeeping_s);
  f.field("teardown_s", v.teardown_s);
  f.field("parent_s", v.parent_s);
  f.field("harness_overhead_s", v.harness_overhead_s);
  f.done();
}

namespace {

// CellResults is written into, and read from, the object of the cell it belongs to.
void put_fields(json& j, const CellResults& v) {
  put(j, "geometry_hash", v.geometry_hash);
  put(j, "counts", v.counts);
  put(j, "output_bytes", v.output_bytes);
  put(j, "metrics", v.metrics);
  put(j, "total_length_m", v.total_length_m);
  put(j, "steps", v.steps);
  put(j, "stopped_by", v.stopped_by);
  put(j, "curve", v.curve);
  put(j, "params", v.params);
  put(j, "algorithm_stats", v.algorithm_stats);
  put(j, "threads", v.threads);
  put(j, "scene_hash", v.scene_hash);
  put(j, "alloc", v.alloc);
  put(j, "instructions", v.instructions);
  put(j, "organs", v.organs);
}
void read_fields(Fields& f, CellResults& v) {
  f.field("geometry_hash", v.geometry_hash);
  f.field("counts", v.counts);
  f.field("output_bytes", v.output_bytes);
  f.field("metrics", v.metrics);
  f.field("total_length_m", v.total_length_m);
  f.field("steps", v.steps);
  f.field("stopped_by", v.stopped_by);
  f.field("curve", v.curve);
  f.field("params", v.params);
  f.field("algorithm_stats", v.algorithm_stats);
  f.field("threads", v.threads);
  f.field("scene_hash", v.scene_hash);
  f.field("alloc", v.alloc);
  f.field("instructions", v.instructions);
  f.field("organs", v.organs);
}

}  // namespace

json to_json(const CellResults& v) {
  json j = json::object();
  put_fields(j, v);
  return j;
}
void read(const Node& n, CellResults& v) {
  Fields f(n);
  read_fields(f, v);
  f.done();
}

json to_json(const MedianSummary& v) {
  return {{"n", v.n}, {"median", v.median}, {"lo", v.lo}, {"hi", v.hi}, {"exact", v.exact}};
}
void read(const Node& n, MedianSummary& v) {
  Fields f(n);
  f.field("n", v.n);
  f.field("median", v.median);
  f.field("lo", v.lo);
  f.field("hi", v.hi);
  f.field("exact", v.exact);
  f.done();
}

json to_json(const CellSummary& v) {
  json j = json::object();
  put(j, "growth_s", v.growth_s);
  return j;
}
void read(const Node& n, CellSummary& v) {
  Fields f(n);
  f.field("growth_s", v.growth_s);
  f.done();
}

json to_json(const JournalEntry& v) {
  return {{"id", v.id}, {"sample", to_json(v.sample)}, {"cell", v.cell ? to_json(*v.cell) : json(nullptr)}};
}
void read(const Node& n, JournalEntry& v) {
  Fields f(n);
  f.required("id", v.id);
  f.field("sample", v.sample);
  f.field("cell", v.cell);
  f.done();
}

json to_json(const SuiteCell& v) {
  json j = {{"id", v.id},
            {"label", v.label},
            {"algorithm", v.algorithm},
            {"scene", v.scene},
            {"scene_spec", v.scene_spec},
            {"seed", v.seed},
            {"sweep", v.sweep},
            {"spec", to_json(v.spec)},
            {"status", v.status},
            {"samples", to_json_value(v.samples)}};
  put(j, "message", v.message);
  put(j, "nondeterministic", v.nondeterministic);
  put_fields(j, v.results);
  put(j, "summary", v.summary);
  put(j, "render", v.render);
  put(j, "animation", v.animation);
  put(j, "turntable", v.turntable);
  return j;
}
void read(const Node& n, SuiteCell& v) {
  Fields f(n);
  f.required("id", v.id);
  f.field("label", v.label);
  f.field("algorithm", v.algorithm);
  f.field("scene", v.scene);
  f.field("scene_spec", v.scene_spec);
  f.field("seed", v.seed);
  f.field("sweep", v.sweep);
  f.field("spec", v.spec);
  f.field("status", v.status);
  f.field("message", v.message);
  f.field("nondeterministic", v.nondeterministic);
  f.field("samples", v.samples);
  read_fields(f, v.results);
  f.field("summary", v.summary);
  f.field("render", v.render);
  f.field("animation", v.animation);
  f.field("turntable", v.turntable);
  f.done();
}

json to_json(const SuiteInfo& v) {
  return {{"name", v.name}, {"file", v.file}, {"description", v.description}};
}
void read(const Node& n, SuiteInfo& v) {
  Fields f(n);
  f.field("name", v.name);
  f.field("file", v.file);
  f.field("description", v.description);
  f.done();
}

json to_json(const ShardInfo& v) {
  return {{"index", v.index}, {"count", v.count}};
}
void read(const Node& n, ShardInfo& v) {
  Fields f(n);
  f.field("index", v.index);
  f.field("count", v.count);
  f.done();
}

json to_json(const ShardRecord& v) {
  return {{"index", v.index}, {"file", v.file}, {"context", to_json(v.context)}};
}
void read(const Node& n, ShardRecord& v) {
  Fields f(n);
  f.field("index", v.index);
  f.field("file", v.file);
  f.field("context", v.context);
  f.done();
}

json to_json(const RenderSummary& v) {
  json j = {{"quality", v.quality},
            {"branches", v.branches},
            {"width", v.width},
            {"height", v.height},
            {"povray", v.povray},
            {"jobs", v.jobs},
            {"threads_per_render", v.threads_per_render},
            {"renders", v.renders},
            {"ok", v.ok},
            {"failed", v.failed},
            {"warnings", v.warnings},
            {"skipped_without_snapshot", v.skipped_without_snapshot},
            {"povray_s", v.povray_s},
            {"wall_s", v.wall_s}};
  put(j, "grid", v.grid);
  put(j, "grid_per_scene", v.grid_per_scene);
  put(j, "grid_error", v.grid_error);
  put(j, "camera", v.camera);
  put(j, "backdrop", v.backdrop);
  put(j, "dof", v.dof);
  put(j, "turntable", v.turntable);
  return j;
}
void read(const Node& n, RenderSummary& v) {
  Fields f(n);
  f.field("quality", v.quality);
  f.field("branches", v.branches);
  f.field("width", v.width);
  f.field("height", v.height);
  f.field("povray", v.povray);
  f.field("jobs", v.jobs);
  f.field("threads_per_render", v.threads_per_render);
  f.field("renders", v.renders);
  f.field("ok", v.ok);
  f.field("failed", v.failed);
  f.field("warnings", v.warnings);
  f.field("skipped_without_snapshot", v.skipped_without_snapshot);
  f.field("povray_s", v.povray_s);
  f.field("wall_s", v.wall_s);
  f.field("grid", v.grid);
  f.field("grid_per_scene", v.grid_per_scene);
  f.field("grid_error", v.grid_error);
  f.field("camera", v.camera);
  f.field("backdrop", v.backdrop);
  f.field("dof", v.dof);
  f.field("turntable", v.turntable);
  f.done();
}

json to_json(const PooledSummary& v) {
  return {{"label", v.label},
          {"scene", v.scene},
          {"sweep", v.sweep},
          {"cells", v.cells},
          {"growth_s", to_json(v.growth_s)}};
}
void read(const Node& n, PooledSummary& v) {
  Fields f(n);
  f.field("label", v.label);
  f.field("scene", v.scene);
  f.field("sweep", v.sweep);
  f.field("cells", v.cells);
  f.field("growth_s", v.growth_s);
  f.done();
}

json to_json(const ResultsSummary& v) {
  return {{"growth_s_over_seeds", to_json_value(v.growth_s_over_seeds)}};
}
void read(const Node& n, ResultsSummary& v) {
  Fields f(n);
  f.field("growth_s_over_seeds", v.growth_s_over_seeds);
  f.done();
}

json to_json(const ResultsFile& v) {
  json j = {{"schema_version", v.schema_version},
            {"kind", v.kind},
            {"mode", v.mode},
            {"suite", to_json(v.suite)},
            {"suite_hash", v.suite_hash},
            {"repetitions", v.repetitions},
            {"shard", to_json(v.shard)},
            {"context", to_json(v.context)},
            {"trials", to_json_value(v.trials)}};
  put(j, "shards", v.shards);
  put(j, "renders", v.renders);
  put(j, "summary", v.summary);
  return j;
}
void read(const Node& n, ResultsFile& v) {
  Fields f(n);
  f.field("schema_version", v.schema_version);
  f.required("kind", v.kind);
  f.field("mode", v.mode);
  f.field("suite", v.suite);
  f.field("suite_hash", v.suite_hash);
  f.field("repetitions", v.repetitions);
  f.field("shard", v.shard);
  f.field("context", v.context);
  f.required("trials", v.trials);
  f.field("shards", v.shards);
  f.field("renders", v.renders);
  f.field("summary", v.summary);
  f.done();
}

json to_json(const BaselineContext& v) {
  return {{"growbench_commit", v.growbench_commit},
          {"dirty", v.dirty},
          {"compiler", v.compiler},
          {"cxx_flags", v.cxx_flags},
          {"build_type", v.build_type},
          {"dependencies", v.dependencies}};
}
void read(const Node& n, BaselineContext& v) {
  Fields f(n);
  f.field("growbench_commit", v.growbench_commit);
  f.field("dirty", v.dirty);
  f.field("compiler", v.compiler);
  f.field("cxx_flags", v.cxx_flags);
  f.field("build_type", v.build_type);
  f.field("dependencies", v.dependencies);
  f.done();
}

json to_json(const BaselineCell& v) {
  json j = {{"id", v.id},       {"label", v.label}, {"algorithm", v.algorithm},
            {"scene", v.scene}, {"seed", v.seed},   {"status", v.status}};
  put(j, "threads", v.threads);
  put(j, "geometry_hash", v.geometry_hash);
  put(j, "counts", v.counts);
  put(j, "metrics", v.metrics);
  put(j, "output_bytes", v.output_bytes);
  put(j, "alloc", v.alloc);
  put(j, "instructions", v.instructions);
  return j;
}
void read(const Node& n, BaselineCell& v) {
  Fields f(n);
  f.required("id", v.id);
  f.field("label", v.label);
  f.field("algorithm", v.algorithm);
  f.field("scene", v.scene);
  f.field("seed", v.seed);
  f.field("status", v.status);
  f.field("threads", v.threads);
  f.field("geometry_hash", v.geometry_hash);
  f.field("counts", v.counts);
  f.field("metrics", v.metrics);
  f.field("output_bytes", v.output_bytes);
  f.field("alloc", v.alloc);
  f.field("instructions", v.instructions);
  f.done();
}

json to_json(const Baseline& v) {
  return {{"schema_version", v.schema_version},
          {"kind", v.kind},
          {"mode", v.mode},
          {"suite", to_json(v.suite)},
          {"suite_hash", v.suite_hash},
          {"context", to_json(v.context)},
          {"trials", to_json_value(v.trials)}};
}
void read(const Node& n, Baseline& v) {
  Fields f(n);
  f.field("schema_version", v.schema_version);
  f.required("kind", v.kind);
  f.field("mode", v.mode);
  f.field("suite", v.suite);
  f.field("suite_hash", v.suite_hash);
  f.field("context", v.context);
  f.required("trials", v.trials);
  f.done();
}

json to_json(const HistoryCell& v) {
  json j = {{"status", v.status}};
  put(j, "geometry_hash", v.geometry_hash);
  put(j, "nodes", v.nodes);
  put(j, "total_wall_s", v.total_wall_s);
  put(j, "total_wall_s_n", v.total_wall_s_n);
  put(j, "growth_wall_s", v.growth_wall_s);
  put(j, "growth_wall_s_n", v.growth_wall_s_n);
  put(j, "growth_cpu_s", v.growth_cpu_s);
  put(j, "growth_cpu_s_n", v.growth_cpu_s_n);
  put(j, "growth_peak_rss_bytes", v.growth_peak_rss_bytes);
  put(j, "growth_peak_rss_bytes_n", v.growth_peak_rss_bytes_n);
  put(j, "instructions", v.instructions);
  return j;
}
void read(const Node& n, HistoryCell& v) {
  Fields f(n);
  f.field("status", v.status);
  f.field("geometry_hash", v.geometry_hash);
  f.field("nodes", v.nodes);
  f.field("total_wall_s", v.total_wall_s);
  f.field("total_wall_s_n", v.total_wall_s_n);
  f.field("growth_wall_s", v.growth_wall_s);
  f.field("growth_wall_s_n", v.growth_wall_s_n);
  f.field("growth_cpu_s", v.growth_cpu_s);
  f.field("growth_cpu_s_n", v.growth_cpu_s_n);
  f.field("growth_peak_rss_bytes", v.growth_peak_rss_bytes);
  f.field("growth_peak_rss_bytes_n", v.growth_peak_rss_bytes_n);
  f.field("instructions", v.instructions);
  f.done();
}

json to_json(const HistoryRun& v) {
  return {{"date", v.date},
          {"mode", v.mode},
          {"dirty", v.dirty},
          {"build_type", v.build_type},
          {"cells", to_json_value(v.cells)}};
}
void read(const Node& n, HistoryRun& v) {
  Fields f(n);
  f.field("date", v.date);
  f.field("mode", v.mode);
  f.field("dirty", v.dirty);
  f.field("build_type", v.build_type);
  f.field("cells", v.cells);
  f.done();
}

json to_json(const HistoryFile& v) {
  json j = {{"kind", v.kind},       {"schema_version", v.schema_version}, {"commit", v.commit},
            {"machine", v.machine}, {"cpu_model", v.cpu_model},           {"hardware_threads", v.hardware_threads},
            {"suite", v.suite},     {"runs", to_json_value(v.runs)}};
  put_nullable(j, "commit_time", v.commit_time);
  return j;
}
void read(const Node& n, HistoryFile& v) {
  Fields f(n);
  f.required("kind", v.kind);
  f.field("schema_version", v.schema_version);
  f.field("commit", v.commit);
  f.field("commit_time", v.commit_time);
  f.field("machine", v.machine);
  f.field("cpu_model", v.cpu_model);
  f.field("hardware_threads", v.hardware_threads);
  f.field("suite", v.suite);
  f.field("runs", v.runs);
  f.done();
}

// ---------------------------------------------------------------- entry points

template <class T>
T from_json(const json& j, const std::string& source) {
  T v;
  read(Node{j, source, ""}, v);
  return v;
}

#define GROWBENCH_RECORD_TYPE(T) template T from_json<T>(const json&, const std::string&);
GROWBENCH_RECORD_TYPE(PhaseMeasures)
GROWBENCH_RECORD_TYPE(Phases)
GROWBENCH_RECORD_TYPE(Counts)
GROWBENCH_RECORD_TYPE(OutputBytes)
GROWBENCH_RECORD_TYPE(Curve)
GROWBENCH_RECORD_TYPE(SceneInfo)
GROWBENCH_RECORD_TYPE(FramesInfo)
GROWBENCH_RECORD_TYPE(OrganPassRecord)
GROWBENCH_RECORD_TYPE(RunContext)
GROWBENCH_RECORD_TYPE(RenderRecord)
GROWBENCH_RECORD_TYPE(AnimationRecord)
GROWBENCH_RECORD_TYPE(TrialRecord)
GROWBENCH_RECORD_TYPE(TrialSpecRecord)
GROWBENCH_RECORD_TYPE(AllocCount)
GROWBENCH_RECORD_TYPE(SuiteSample)
GROWBENCH_RECORD_TYPE(CellResults)
GROWBENCH_RECORD_TYPE(MedianSummary)
GROWBENCH_RECORD_TYPE(CellSummary)
GROWBENCH_RECORD_TYPE(JournalEntry)
GROWBENCH_RECORD_TYPE(SuiteCell)
GROWBENCH_RECORD_TYPE(SuiteInfo)
GROWBENCH_RECORD_TYPE(ShardInfo)
GROWBENCH_RECORD_TYPE(ShardRecord)
GROWBENCH_RECORD_TYPE(RenderSummary)
GROWBENCH_RECORD_TYPE(PooledSummary)
GROWBENCH_RECORD_TYPE(ResultsSummary)
GROWBENCH_RECORD_TYPE(ResultsFile)
GROWBENCH_RECORD_TYPE(BaselineContext)
GROWBENCH_RECORD_TYPE(BaselineCell)
GROWBENCH_RECORD_TYPE(Baseline)
GROWBENCH_RECORD_TYPE(HistoryCell)
GROWBENCH_RECORD_TYPE(HistoryRun)
GROWBENCH_RECORD_TYPE(HistoryFile)
#undef GROWBENCH_RECORD_TYPE

namespace {

json parse_file(const std::string& path) {
  return read_json_file(path);
}

// Before the typed read, so that a newer file's new fields are not taken for mistakes.
void check_version(const json& j, const std::string& path) {
  const json* v = j.is_object() && j.contains("schema_version") ? &j["schema_version"] : nullptr;
  if (v && v->is_number() && v->get<double>() > kSchemaVersion)
    throw InputError(fmt::format("{}: schema_version {} is newer than this growbench reads ({}); use a newer growbench",
                                 path, v->dump(), kSchemaVersion));
}

void check_kind(const json& j, std::string_view kind, const std::string& path, const char* what) {
  const json* k = j.is_object() && j.contains("kind") ? &j["kind"] : nullptr;
  if (!k || *k != kind)
    throw InputError(fmt::format("{}: not a {} (kind {}, expected '{}')", path, what,
                                 k ? k->dump(-1, ' ', false, json::error_handler_t::replace) : "absent", kind));
}

}  // namespace

TrialRecord read_trial_record(const std::string& path) {
  const json j = parse_file(path);
  check_version(j, path);
  return from_json<TrialRecord>(j, path);
}

ResultsFile results_from_json(const json& j, const std::string& path) {
  check_kind(j, kResultsKind, path, "growbench results file");
  check_version(j, path);
  return from_json<ResultsFile>(j, path);
}

ResultsFile read_results(const std::string& path) {
  return results_from_json(parse_file(path), path);
}

Baseline baseline_from_json(const json& j, const std::string& path) {
  check_kind(j, kBaselineKind, path, "growbench baseline");
  check_version(j, path);
  return from_json<Baseline>(j, path);
}

Baseline read_baseline(const std::string& path) {
  return baseline_from_json(parse_file(path), path);
}

HistoryFile read_history_file(const std::string& path) {
  const json j = parse_file(path);
  check_kind(j, kHistoryKind, path, "growbench history file");
  check_version(j, path);
  return from_json<HistoryFile>(j, path);
}

std::vector<JournalEntry> read_journal(const std::string& path) {
  std::vector<JournalEntry> out;
  std::ifstream in(path);
  std::size_t line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    json j;
    try {
      j = json::parse(line);
    } catch (const json::exception&) {
      continue;  // a line cut short by a kill: its trial runs again
    }
    out.push_back(from_json<JournalEntry>(j, fmt::format("{}:{}", path, line_no)));
  }
  return out;
}

std::string repair_journal(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size == 0) return "";
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open the journal: {}", path, std::strerror(errno)));
  // The last line: read back from the end in blocks until a newline.
  std::string tail;
  std::uintmax_t start = size;
  for (std::uintmax_t block = 4096; start > 0; block *= 2) {
    const std::uintmax_t from = start > block ? start - block : 0;
    std::string chunk(static_cast<std::size_t>(start - from), '\0');
    in.seekg(static_cast<std::streamoff>(from));
    if (!in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())))
      throw InputError(fmt::format("{}: cannot read the journal", path));
    tail.insert(0, chunk);
    start = from;
    if (const auto nl = tail.rfind('\n'); nl != std::string::npos) {
      if (nl + 1 == tail.size()) return "";  // ends with a newline: nothing torn
      start += nl + 1;
      tail.erase(0, nl + 1);
      break;
    }
  }
  in.close();
  bool whole = false;
  try {
    (void)from_json<JournalEntry>(json::parse(tail), path);
    whole = true;
  } catch (const std::exception&) {
  }
  if (whole) {
    append_to_file(path, "\n");
    return "";
  }
  append_to_file(path + ".torn", tail + "\n");  // first, so that the bytes are kept whatever happens next
  std::filesystem::resize_file(path, start, ec);
  if (ec) throw InputError(fmt::format("{}: cannot cut off its torn last line: {}", path, ec.message()));
  return tail;
}

std::string json_text(const json& j, int indent) {
  return j.dump(indent, ' ', false, json::error_handler_t::replace) + "\n";
}

}  // namespace growbench
