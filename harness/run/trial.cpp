#include "harness/run/trial.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>
#include <sys/resource.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>
#include <vector>

#include <embree3/rtcore_config.h>
#include <fmt/format.h>
#include <openvdb/version.h>
#include <tbb/global_control.h>
#include <tbb/version.h>
#include <valgrind/callgrind.h>
#include <xxhash.h>

#include "algorithms/algorithm.hpp"
#include "core/errors.hpp"
#include "harness/record/files.hpp"
#include "harness/run/alloc_counter.hpp"
#include "harness/output/exporters.hpp"
#include "harness/output/metrics.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"

#ifndef GROWBENCH_GIT_COMMIT
#define GROWBENCH_GIT_COMMIT "unknown"
#endif
#ifndef GROWBENCH_SOURCE_DIR
#define GROWBENCH_SOURCE_DIR ""
#endif

namespace growbench {
namespace {

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// A /proc/self file kept open for this process (a forked child opens its own): each phase reads
// VmHWM and resets it, and on a paravirtualised VM every open/close costs tens of microseconds.
int proc_self_fd(const char* name, int flags) {
  struct Cached {
    pid_t pid = -1;
    int fd = -1;
  };
  static std::map<std::string, Cached> cache;
  Cached& c = cache[name];
  if (c.pid != getpid()) {
    c.fd = open((std::string("/proc/self/") + name).c_str(), flags | O_CLOEXEC);  // the parent's fd is not ours
    c.pid = getpid();
  }
  return c.fd;
}

std::uint64_t status_kb(const char* key) {
  const int fd = proc_self_fd("status", O_RDONLY);
  char buf[8192];
  const ssize_t n = fd >= 0 ? pread(fd, buf, sizeof buf - 1, 0) : -1;
  if (n <= 0) return 0;
  buf[n] = '\0';
  const std::string pattern = std::string("\n") + key + ":";
  const char* at = std::strstr(buf, pattern.c_str());
  return at ? std::strtoull(at + pattern.size(), nullptr, 10) : 0;
}

// Resets the kernel's peak-RSS mark (VmHWM) to the current RSS, so each phase's peak is its own.
bool reset_peak_rss() {
  const int fd = proc_self_fd("clear_refs", O_WRONLY);
  return fd >= 0 && pwrite(fd, "5", 1, 0) == 1;
}

class PhaseTimer {
 public:
  explicit PhaseTimer(nlohmann::json& phases) : phases_(phases) {}
  template <class F>
  auto run(const char* name, F&& f) {
    const bool reset = reset_peak_rss();
    // Under callgrind (`growbench suite --instructions`, which starts with instrumentation off) each
    // phase is instrumented and dumped on its own; natively these are a few no-op instructions. The
    // query build (OpenVDB's level set and Embree's BVH, the same for every algorithm) is left
    // uninstrumented: at about 50x it would take most of the gate's time (2.5 G instructions on the wall).
    const bool instrument = std::strcmp(name, "query_build") != 0;
    if (instrument) {
      CALLGRIND_ZERO_STATS;
      CALLGRIND_START_INSTRUMENTATION;
    }
    const AllocStats a0 = alloc_stats();
    const auto w0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    auto record = [&] {
      if (instrument) {
        CALLGRIND_DUMP_STATS_AT(name);
        CALLGRIND_STOP_INSTRUMENTATION;
      }
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
      const double cpu = cpu_seconds() - c0;
      const AllocStats a1 = alloc_stats();
      phases_[name] = {{"wall_s", wall},
                       {"cpu_s", cpu},
                       {"peak_rss_bytes", status_kb("VmHWM") * 1024u},
                       {"peak_rss_reset", reset},
                       {"alloc_count", a1.count - a0.count},
                       {"alloc_bytes", a1.bytes - a0.bytes}};
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

std::string run_command(const std::string& cmd) {
  std::string out;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[256];
    while (std::fgets(buf, sizeof(buf), p)) out += buf;
    pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

// A growth curve that keeps at most 2 * kCurveCap points: when full, every other point is dropped and
// the sampling interval doubles (deterministic for a given run).
constexpr std::size_t kCurveCap = 256;
struct Curve {
  int every = 1;
  std::vector<int> steps;
  std::vector<std::size_t> nodes, organs;
  std::vector<double> wall_s;
  void add(int step, std::size_t n, std::size_t o, double t) {
    if (step % every != 0) return;
    steps.push_back(step);
    nodes.push_back(n);
    organs.push_back(o);
    wall_s.push_back(t);
    if (steps.size() >= 2 * kCurveCap) {
      auto halve = [](auto& v) {
        std::size_t w = 0;
        for (std::size_t i = 1; i < v.size(); i += 2) v[w++] = v[i];
        v.resize(w);
      };
      halve(steps);
      halve(nodes);
      halve(organs);
      halve(wall_s);
      every *= 2;
    }
  }
};

void inject_fault(const std::string& fault) {
  if (fault.empty()) return;
  if (fault == "crash") std::raise(SIGSEGV);
  if (fault == "hang")
    for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
  if (fault == "oom") {
    std::vector<std::unique_ptr<char[]>> hog;
    for (;;) {
      hog.emplace_back(new char[64 << 20]);
      std::fill_n(hog.back().get(), 64 << 20, 1);
    }
  }
  if (fault == "throw") throw std::runtime_error("injected internal error");
  if (fault.rfind("slow:", 0) == 0) {
    // A planted slowdown for testing the regression gates: this much extra work in the growth phase,
    // the plant unchanged.
    std::uint64_t n = 0;
    try {
      n = std::stoull(fault.substr(5));
    } catch (const std::exception&) {
      throw InputError(fmt::format("fault '{}': expected slow:N with N a count of iterations", fault));
    }
    volatile std::uint64_t sink = 0;
    std::uint64_t h = 0x9E3779B97F4A7C15ull;
    for (std::uint64_t i = 0; i < n; ++i) h = (h ^ (h >> 31)) * 0xBF58476D1CE4E5B9ull + i;
    sink = h;
    (void)sink;
    return;
  }
  throw InputError(fmt::format("unknown fault '{}'; expected crash, hang, oom, throw or slow:N", fault));
}

}  // namespace

// The running binary's content hash: what identifies the build whose timings these are, whatever the
// source tree's state is by the time it runs (a commit made while a sharded run is under way).
std::string binary_hash() {
  std::ifstream in("/proc/self/exe", std::ios::binary);
  XXH3_state_t* st = XXH3_createState();
  XXH3_64bits_reset(st);
  std::vector<char> buf(1 << 16);
  while (in.read(buf.data(), static_cast<std::streamsize>(buf.size())) || in.gcount() > 0)
    XXH3_64bits_update(st, buf.data(), static_cast<std::size_t>(in.gcount()));
  const std::uint64_t h = XXH3_64bits_digest(st);
  XXH3_freeState(st);
  return in.bad() ? std::string("unknown") : fmt::format("{:016x}", h);
}

nlohmann::json run_context() {
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof(date), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  // The commit the binary was configured at; the source tree's current state when it is reachable.
  std::string commit = GROWBENCH_GIT_COMMIT;
  std::string dirty = "unknown";
  nlohmann::json commit_time = nullptr;  // committer time (Unix seconds): orders a history by commit
  if (std::filesystem::exists(std::string(GROWBENCH_SOURCE_DIR) + "/.git")) {
    const std::string c = run_command(fmt::format("git -C '{}' rev-parse --short=12 HEAD 2>/dev/null", GROWBENCH_SOURCE_DIR));
    if (!c.empty()) commit = c;
    const std::string ct = run_command(fmt::format("git -C '{}' show -s --format=%ct HEAD 2>/dev/null", GROWBENCH_SOURCE_DIR));
    if (!ct.empty() && ct.find_first_not_of("0123456789") == std::string::npos) commit_time = std::stoll(ct);
    dirty = run_command(fmt::format("git -C '{}' status --porcelain --untracked-files=no 2>/dev/null", GROWBENCH_SOURCE_DIR)).empty()
                ? "false"
                : "true";
  }
  return {{"growbench_commit", commit},
          {"dirty", dirty},
          {"commit_time", commit_time},
          {"configured_commit", GROWBENCH_GIT_COMMIT},
          {"build_type", GROWBENCH_BUILD_TYPE},
          {"compiler", fmt::format("g++ {}", __VERSION__)},
          {"cxx_flags", GROWBENCH_CXX_FLAGS},
          {"binary_hash", binary_hash()},
          {"cpu_model", cpu_model()},
          {"hardware_threads", std::thread::hardware_concurrency()},
          {"date", date},
          {"alloc_counting", alloc_counting_enabled()},
          {"dependencies",
           {{"embree", fmt::format("{}.{}.{}", RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH)},
            {"openvdb", OPENVDB_LIBRARY_VERSION_STRING},
            {"tbb", TBB_VERSION_STRING},
            {"fmt", FMT_VERSION}}}};
}

nlohmann::json to_json(const TrialSpec& s) {
  nlohmann::json seeds = nlohmann::json::array();
  for (const auto& p : s.seed_at) seeds.push_back({p.x, p.y, p.z});
  nlohmann::json j = {{"algorithm", s.algorithm},       {"scene", s.scene},
          {"scene_params", s.scene_params}, {"params", s.params},
          {"seed", s.seed},                 {"seed_at", seeds},
          {"max_steps", s.max_steps},       {"time_limit_s", s.time_limit_s},
          {"threads", s.threads},           {"voxel_size", s.voxel_size},
          {"sides", s.mesher.sides},        {"budget_nodes", s.budget_nodes},
          {"budget_length_m", s.budget_length_m}, {"metrics", s.metrics},
          {"frame_every", s.frame_every},
          {"fault", s.fault}};
  if (!s.mesher.leaf_obj.empty()) j["leaf_obj"] = s.mesher.leaf_obj;  // only when given: older specs stay as they were
  return j;
}

TrialSpec trial_spec_from_json(const nlohmann::json& j) {
  TrialSpec s;
  s.algorithm = j.at("algorithm").get<std::string>();
  s.scene = j.at("scene").get<std::string>();
  s.scene_params = j.value("scene_params", std::vector<std::string>{});
  s.params = j.value("params", std::vector<std::string>{});
  s.seed = j.value("seed", std::uint64_t{1});
  for (const auto& p : j.value("seed_at", nlohmann::json::array()))
    s.seed_at.emplace_back(p[0].get<float>(), p[1].get<float>(), p[2].get<float>());
  s.max_steps = j.value("max_steps", 5000);
  s.time_limit_s = j.value("time_limit_s", 0.0);
  s.threads = j.value("threads", 0);
  s.voxel_size = j.value("voxel_size", 0.0f);
  s.mesher.sides = j.value("sides", 6);
  s.mesher.leaf_obj = j.value("leaf_obj", std::string{});
  s.budget_nodes = j.value("budget_nodes", std::size_t{0});
  s.budget_length_m = j.value("budget_length_m", 0.0);
  s.metrics = j.value("metrics", true);
  s.frame_every = j.value("frame_every", 0);
  // Only in the spec file a suite hands to `growbench trial` (not in results):
  s.out_dir = j.value("out_dir", std::string{});
  s.context = j.value("context", true);
  s.skip_teardown = j.value("skip_teardown", false);
  s.fault = j.value("fault", std::string{});
  return s;
}

nlohmann::json run_trial(const TrialSpec& spec, const std::function<void(const Progress&)>& progress, Plant* plant_out) {
  const AlgorithmEntry& entry = find_algorithm(spec.algorithm);
  Params params = default_params(entry);
  for (const auto& a : spec.params) params.set_assignment(a);
  if (spec.max_steps < 0) throw InputError(fmt::format("--max-steps must be >= 0, got {}", spec.max_steps));
  if (spec.frame_every < 0) throw InputError(fmt::format("--frames must be >= 0, got {}", spec.frame_every));
  if (spec.frame_every > 0 && spec.out_dir.empty()) throw InputError("--frames needs an output directory");

  // A custom leaf is read first: a bad file is invalid input before anything is grown.
  const MesherOptions mesher = with_leaf_mesh(spec.mesher);
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
  if (!spec.mesher.leaf_obj.empty()) rec["leaf_obj"] = spec.mesher.leaf_obj;

  std::unique_ptr<GrowthAlgorithm> algo = entry.make();
  int steps = 0;
  std::string stopped_by = "finished";
  Curve curve;
  // Frame capture (growth animations): its cost is measured and taken out of the growth phase.
  int frames = 0, last_frame = -1;
  double frame_wall = 0.0, frame_cpu = 0.0;
  auto capture = [&](int step) {
    if (spec.frame_every <= 0 || step == last_frame) return;
    const auto w0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    const std::filesystem::path d = std::filesystem::path(spec.out_dir) / "frames";
    if (frames == 0) {
      std::filesystem::remove_all(d);
      std::filesystem::create_directories(d);
    }
    write_plant_snapshot((d / fmt::format("step_{:06d}.gbplant", step)).string(), algo->plant());
    ++frames;
    last_frame = step;
    frame_wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    frame_cpu += cpu_seconds() - c0;
  };
  timer.run("growth", [&] {
    inject_fault(spec.fault);
    algo->start(scene, *query, params, spec.seed);
    const auto t0 = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    curve.add(0, algo->node_count(), algo->organ_count(), elapsed());
    while (true) {
      if (steps >= spec.max_steps) {
        stopped_by = "max_steps";
        break;
      }
      if (spec.time_limit_s > 0.0 && elapsed() > spec.time_limit_s) {
        stopped_by = "time_limit";
        break;
      }
      if (spec.budget_nodes > 0 && algo->node_count() >= spec.budget_nodes) {
        stopped_by = "budget_nodes";
        break;
      }
      if (spec.budget_length_m > 0.0 && algo->plant().total_length() >= spec.budget_length_m) {
        stopped_by = "budget_length";
        break;
      }
      const bool more = algo->step();
      ++steps;
      const double t = elapsed();
      curve.add(steps, algo->node_count(), algo->organ_count(), t);
      if (progress) progress({steps, algo->node_count(), t});
      if (spec.frame_every > 0 && steps % spec.frame_every == 0 && more) capture(steps);
      if (!more) break;
    }
    algo->finish();
    capture(steps);
  });
  if (spec.frame_every > 0) {
    phases["growth"]["wall_s"] = phases["growth"]["wall_s"].get<double>() - frame_wall;
    phases["growth"]["cpu_s"] = phases["growth"]["cpu_s"].get<double>() - frame_cpu;
    phases["growth"]["frame_capture_wall_s"] = frame_wall;
    phases["growth"]["frame_capture_cpu_s"] = frame_cpu;
    rec["frames"] = {{"every", spec.frame_every}, {"count", frames}, {"dir", "frames"}};
  }
  const Plant& plant = algo->plant();
  if (const std::string bad = plant.validate(); !bad.empty())
    throw std::logic_error(fmt::format("algorithm '{}' produced an invalid plant: {}", spec.algorithm, bad));
  if (plant_out) *plant_out = plant;
  rec["steps"] = steps;
  rec["stopped_by"] = stopped_by;
  rec["curve"] = {{"every", curve.every},
                  {"step", curve.steps},
                  {"nodes", curve.nodes},
                  {"organs", curve.organs},
                  {"wall_s", curve.wall_s}};

  // The plant itself, for rendering later (`growbench render`); not an output format, not timed. Written
  // before the exports: after them, tens of MB of dirty pages can make the kernel throttle this write.
  if (!spec.out_dir.empty()) {
    std::filesystem::create_directories(spec.out_dir);
    rec["snapshot_bytes"] = write_plant_snapshot((std::filesystem::path(spec.out_dir) / "plant.gbplant").string(), plant);
  }
  OutputMesh mesh = timer.run("meshing", [&] { return mesh_plant(plant, mesher); });

  nlohmann::json bytes = nlohmann::json::object();
  timer.run("export", [&] {
    if (spec.out_dir.empty()) return;
    std::filesystem::create_directories(spec.out_dir);
    const std::filesystem::path d(spec.out_dir);
    bytes["obj"] = write_obj((d / "plant.obj").string(), mesh);
    bytes["ply"] = write_ply((d / "plant.ply").string(), mesh);
    bytes["glb"] = write_glb((d / "plant.glb").string(), mesh);
    bytes["skeleton_obj"] = write_skeleton_obj((d / "skeleton.obj").string(), plant);
  });
  if (spec.metrics) {
    MetricOptions metric_options;
    metric_options.organ_shape = organ_shape(mesher);
    rec["metrics"] = timer.run("metrics", [&] { return compute_metrics(plant, *query, metric_options); });
  }

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
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  rec["peak_rss_bytes"] = static_cast<std::uint64_t>(ru.ru_maxrss) * 1024u;  // whole process, never reset
  rec["status"] = "ok";
  if (spec.context) rec["context"] = run_context();

  if (!spec.out_dir.empty()) {
    const std::string path = (std::filesystem::path(spec.out_dir) / "record.json").string();
    // Indented for people reading `growbench run` output; compact when a suite parent parses it.
    const std::string text = rec.dump(spec.skip_teardown ? -1 : 2) + "\n";
    write_file_atomic(path, text);
  }
  if (spec.skip_teardown) {
    struct Kept {
      Scene scene;
      std::unique_ptr<SceneQuery> query;
      std::unique_ptr<GrowthAlgorithm> algo;
      OutputMesh mesh;
    };
    // Deliberately never freed: the process exits next and the kernel reclaims it all at once.
    [[maybe_unused]] auto* kept = new Kept{std::move(scene), std::move(query), std::move(algo), std::move(mesh)};
  }
  return rec;
}

}  // namespace growbench
