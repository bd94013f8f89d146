#include "harness/trial.hpp"

#include <sys/resource.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <thread>

#include <embree3/rtcore_config.h>
#include <fmt/format.h>
#include <tbb/global_control.h>
#include <tbb/version.h>

#include "algorithms/algorithm.hpp"
#include "core/errors.hpp"
#include "harness/exporters.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"

#ifndef GROWBENCH_GIT_COMMIT
#define GROWBENCH_GIT_COMMIT "unknown"
#endif
#ifndef GROWBENCH_BUILD_TYPE
#define GROWBENCH_BUILD_TYPE "unknown"
#endif
#ifndef GROWBENCH_CXX_FLAGS
#define GROWBENCH_CXX_FLAGS ""
#endif

namespace growbench {
namespace {

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::uint64_t peak_rss_bytes() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<std::uint64_t>(ru.ru_maxrss) * 1024u;
}

class PhaseTimer {
 public:
  explicit PhaseTimer(nlohmann::json& phases) : phases_(phases) {}
  template <class F>
  auto run(const char* name, F&& f) {
    const auto w0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    auto record = [&] {
      phases_[name] = {{"wall_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count()},
                       {"cpu_s", cpu_seconds() - c0},
                       {"peak_rss_bytes", peak_rss_bytes()}};
    };
    if constexpr (std::is_void_v<decltype(f())>) {
      f();
      record();
    } else {
      auto r = f();
      record();
      return r;
    }
  }

 private:
  nlohmann::json& phases_;
};

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

}  // namespace

nlohmann::json run_context() {
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof(date), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return {{"growbench_commit", GROWBENCH_GIT_COMMIT},
          {"build_type", GROWBENCH_BUILD_TYPE},
          {"compiler", fmt::format("{} {}", "g++", __VERSION__)},
          {"cxx_flags", GROWBENCH_CXX_FLAGS},
          {"cpu_model", cpu_model()},
          {"hardware_threads", std::thread::hardware_concurrency()},
          {"date", date},
          {"dependencies",
           {{"embree", fmt::format("{}.{}.{}", RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH)},
            {"tbb", TBB_VERSION_STRING},
            {"fmt", FMT_VERSION}}}};
}

nlohmann::json run_trial(const TrialSpec& spec, const std::function<void(const Progress&)>& progress, Plant* plant_out) {
  const AlgorithmEntry& entry = find_algorithm(spec.algorithm);
  Params params = default_params(entry);
  for (const auto& a : spec.params) params.set_assignment(a);
  if (spec.max_steps < 0) throw InputError(fmt::format("--max-steps must be >= 0, got {}", spec.max_steps));

  std::unique_ptr<tbb::global_control> threads;
  if (spec.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<std::size_t>(spec.threads));
  const auto used_threads = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);

  nlohmann::json rec;
  rec["schema_version"] = 1;
  rec["algorithm"] = spec.algorithm;
  rec["seed"] = spec.seed;
  rec["threads"] = used_threads;
  rec["max_steps"] = spec.max_steps;
  nlohmann::json& phases = rec["phases"];
  PhaseTimer timer(phases);

  Scene scene = timer.run("scene_load", [&] { return load_scene(spec.scene, spec.scene_params); });
  SceneQueryOptions qo;
  qo.voxel_size = spec.voxel_size;
  auto query = timer.run("query_build", [&] { return std::make_unique<SceneQuery>(scene, qo); });
  phases["query_build"]["bvh_s"] = query->bvh_build_seconds();
  phases["query_build"]["sdf_s"] = query->sdf_build_seconds();
  phases["query_build"]["sdf_active_voxels"] = query->sdf_active_voxels();
  phases["query_build"]["voxel_size_m"] = query->voxel_size();

  if (!spec.seed_at.empty()) {
    scene.seeds.clear();
    for (const auto& p : spec.seed_at) {
      const ClosestHit h = query->closest_point(p);
      scene.seeds.push_back({h.found ? h.point : p, {0, 1, 0}, 0});
    }
  }
  rec["scene"] = {{"spec", spec.scene},
                  {"name", scene.name},
                  {"hash", scene.content_hash()},
                  {"triangles", scene.triangle_count()},
                  {"seeds", scene.seeds.size()},
                  {"params", spec.scene_params}};
  rec["params"] = params.to_json();

  std::unique_ptr<GrowthAlgorithm> algo = entry.make();
  int steps = 0;
  std::string stopped_by = "finished";
  nlohmann::json curve = nlohmann::json::array();
  timer.run("growth", [&] {
    algo->start(scene, *query, params, spec.seed);
    const auto t0 = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    while (true) {
      if (steps >= spec.max_steps) {
        stopped_by = "max_steps";
        break;
      }
      if (spec.time_limit_s > 0.0 && elapsed() > spec.time_limit_s) {
        stopped_by = "time_limit";
        break;
      }
      const bool more = algo->step();
      ++steps;
      if (progress) progress({steps, algo->plant().nodes.size(), elapsed()});
      if (!more) break;
    }
    algo->finish();
  });
  const Plant& plant = algo->plant();
  if (const std::string bad = plant.validate(); !bad.empty())
    throw std::logic_error(fmt::format("algorithm '{}' produced an invalid plant: {}", spec.algorithm, bad));
  if (plant_out) *plant_out = plant;
  rec["steps"] = steps;
  rec["stopped_by"] = stopped_by;

  OutputMesh mesh = timer.run("meshing", [&] { return mesh_plant(plant, spec.mesher); });

  nlohmann::json bytes = nlohmann::json::object();
  timer.run("export", [&] {
    if (spec.out_dir.empty()) return;
    std::filesystem::create_directories(spec.out_dir);
    const std::filesystem::path d(spec.out_dir);
    bytes["obj"] = write_obj((d / "plant.obj").string(), mesh);
    bytes["ply"] = write_ply((d / "plant.ply").string(), mesh);
    bytes["skeleton_obj"] = write_skeleton_obj((d / "skeleton.obj").string(), plant);
  });

  std::size_t segments = 0;
  for (const auto& n : plant.nodes) segments += n.parent != kNoParent ? 1 : 0;
  rec["counts"] = {{"nodes", plant.nodes.size()},      {"segments", segments},
                   {"leaves", plant.leaf_count()},     {"organs", plant.organs.size()},
                   {"polygons", plant.polygons.size()}, {"mesh_vertices", mesh.positions.size()},
                   {"mesh_triangles", mesh.triangles.size()}};
  rec["total_length_m"] = plant.total_length();
  rec["output_bytes"] = bytes;
  rec["geometry_hash"] = plant.geometry_hash();
  nlohmann::json stats = nlohmann::json::object();
  for (const auto& [k, v] : algo->stats()) stats[k] = v;
  rec["algorithm_stats"] = stats;
  rec["peak_rss_bytes"] = peak_rss_bytes();
  rec["status"] = "ok";
  rec["context"] = run_context();

  if (!spec.out_dir.empty()) {
    const std::string path = (std::filesystem::path(spec.out_dir) / "record.json").string();
    const std::string text = rec.dump(2) + "\n";
    std::ofstream(path + ".tmp") << text;
    std::filesystem::rename(path + ".tmp", path);
  }
  return rec;
}

}  // namespace growbench
