#include "harness/run/trial.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>
#include <sys/resource.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <new>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <thread>
#include <vector>

#include <embree3/rtcore_config.h>
#include <embree3/rtcore_device.h>
#include <fmt/format.h>
#include <openvdb/version.h>
#include <tbb/global_control.h>
#include <tbb/version.h>
#include <valgrind/callgrind.h>

#include "algorithms/algorithm.hpp"
#include "algorithms/plugins/loader.hpp"
#include "core/data_path.hpp"
#include "core/errors.hpp"
#include "core/file_hash.hpp"
#include "harness/organs/placement.hpp"
#include "harness/record/files.hpp"
#include "harness/record/record.hpp"
#include "harness/run/alloc_counter.hpp"
#include "harness/output/exporters.hpp"
#include "harness/output/metrics.hpp"
#include "harness/output/validity.hpp"
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

// Runs each phase and records what it cost into that phase's slot of the record.
class PhaseTimer {
 public:
  template <class F>
  auto run(Phase phase, Phases& phases, F&& f) {
    std::optional<PhaseMeasures>& slot = phases[phase];
    const char* name = phase_name(phase).data();  // a literal's: null-terminated
    const bool reset = reset_peak_rss();
    // Under callgrind (`growbench suite --instructions`, which starts with instrumentation off) each
    // phase is instrumented and dumped on its own; natively these are a few no-op instructions. The
    // query build (OpenVDB's level set and Embree's BVH, the same for every algorithm) is left
    // uninstrumented: under callgrind's slowdown it would take most of the gate's time.
    const bool instrument = phase != Phase::query_build;
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
      PhaseMeasures& m = slot.emplace();
      m.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
      m.cpu_s = cpu_seconds() - c0;
      const AllocStats a1 = alloc_stats();
      m.peak_rss_bytes = status_kb("VmHWM") * 1024u;
      m.peak_rss_reset = reset;
      m.alloc_count = a1.count - a0.count;
      m.alloc_bytes = a1.bytes - a0.bytes;
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
};

// The first core's clock in MHz: cpufreq's current frequency, else /proc/cpuinfo's (VMs often have only that).
std::optional<double> cpu_mhz() {
  std::ifstream freq("/sys/devices/system/cpu/cpu0/cpufreq/scaling_cur_freq");
  if (double khz = 0.0; freq >> khz && khz > 0.0) return khz / 1000.0;
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("cpu MHz", 0) == 0) {
      const auto colon = line.find(':');
      if (colon == std::string::npos) break;
      try {
        return std::stod(line.substr(colon + 1));
      } catch (const std::exception&) {
        break;
      }
    }
  return std::nullopt;
}

std::optional<std::string> cpu_governor() {
  std::ifstream in("/sys/devices/system/cpu/cpu0/cpufreq/scaling_governor");
  std::string g;
  if (in >> g) return g;
  return std::nullopt;
}

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

// Samples the growth curve, keeping at most 2 * kCurveCap points: when full, every other point is dropped
// and the sampling interval doubles (deterministic for a given run).
constexpr std::size_t kCurveCap = 256;
struct CurveSampler {
  Curve curve;
  void add(int step, std::size_t n, std::size_t o, double t) {
    if (step % curve.every != 0) return;
    curve.step.push_back(step);
    curve.nodes.push_back(n);
    curve.organs.push_back(o);
    curve.wall_s.push_back(t);
    if (curve.step.size() >= 2 * kCurveCap) {
      auto halve = [](auto& v) {
        std::size_t w = 0;
        for (std::size_t i = 1; i < v.size(); i += 2) v[w++] = v[i];
        v.resize(w);
      };
      halve(curve.step);
      halve(curve.nodes);
      halve(curve.organs);
      halve(curve.wall_s);
      curve.every *= 2;
    }
  }
};

// The work a slow:N fault adds, or nothing when `fault` is not one.
std::optional<std::uint64_t> slow_fault_iterations(const std::string& fault) {
  if (fault.rfind("slow:", 0) != 0) return std::nullopt;
  std::uint64_t n = 0;
  const char* last = fault.data() + fault.size();
  const auto r = std::from_chars(fault.data() + 5, last, n);
  if (r.ec != std::errc() || r.ptr != last || fault.size() == 5) return std::nullopt;
  return n;
}

void inject_fault(const std::string& fault) {
  if (const std::string bad = fault_problem(fault); !bad.empty()) throw InputError(bad);
  if (fault == "crash") {
    std::signal(SIGSEGV, SIG_DFL);  // a plain crash, past any handler a sanitizer installed
    std::raise(SIGSEGV);
  }
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
  if (const auto n = slow_fault_iterations(fault)) {
    // A planted slowdown for testing the regression gates: this much extra work in the growth phase,
    // the plant unchanged.
    volatile std::uint64_t sink = 0;
    std::uint64_t h = 0x9E3779B97F4A7C15ull;
    for (std::uint64_t i = 0; i < *n; ++i) h = (h ^ (h >> 31)) * 0xBF58476D1CE4E5B9ull + i;
    sink = h;
    (void)sink;
  }
}

}  // namespace

std::string fault_problem(const std::string& fault) {
  if (fault.empty() || fault == "crash" || fault == "hang" || fault == "oom" || fault == "throw" ||
      slow_fault_iterations(fault))
    return "";
  return fmt::format("unknown fault '{}'; expected crash, hang, oom, throw or slow:N (N a count of iterations)", fault);
}

bool is_out_of_memory(const std::exception& e) {
  if (dynamic_cast<const std::bad_alloc*>(&e)) return true;
  const std::string_view what = e.what();
  return what.rfind("Embree: ", 0) == 0 &&
         what.find(fmt::format("(error {})", static_cast<int>(RTC_ERROR_OUT_OF_MEMORY))) != std::string_view::npos;
}

Outcome outcome_of(const std::exception& e) {
  if (dynamic_cast<const InputError*>(&e)) return Outcome::invalid_input;
  if (dynamic_cast<const PluginError*>(&e)) return Outcome::plugin_error;
  return is_out_of_memory(e) ? Outcome::out_of_memory : Outcome::failed;
}

// The running binary's content hash: what identifies the build whose timings these are, whatever the
// source tree's state is by the time it runs (a commit made while a sharded run is under way).
std::string binary_hash() {
  return file_hash("/proc/self/exe");
}

std::optional<std::array<double, 3>> load_average() {
  std::ifstream in("/proc/loadavg");
  std::array<double, 3> l{};
  if (in >> l[0] >> l[1] >> l[2]) return l;
  return std::nullopt;
}

SourceCommit source_commit() {
  SourceCommit c;
  // The commit the binary was configured at; the source tree's current state when it is reachable.
  c.commit = GROWBENCH_GIT_COMMIT;
  // Not for an installed copy: the checkout may have moved on since it was built.
  if (running_from_build_tree() && std::filesystem::exists(std::string(GROWBENCH_SOURCE_DIR) + "/.git")) {
    const std::string commit =
        run_command(fmt::format("git -C '{}' rev-parse --short=12 HEAD 2>/dev/null", GROWBENCH_SOURCE_DIR));
    if (!commit.empty()) c.commit = commit;
    // Committer time (Unix seconds): orders a history by commit.
    const std::string ct =
        run_command(fmt::format("git -C '{}' show -s --format=%ct HEAD 2>/dev/null", GROWBENCH_SOURCE_DIR));
    if (!ct.empty() && ct.find_first_not_of("0123456789") == std::string::npos) c.time = std::stoll(ct);
    c.dirty = run_command(
                  fmt::format("git -C '{}' status --porcelain --untracked-files=no 2>/dev/null", GROWBENCH_SOURCE_DIR))
                      .empty()
                  ? "false"
                  : "true";
  }
  return c;
}

std::string version_line() {
  const SourceCommit c = source_commit();
  return fmt::format("growbench {} (commit {}{}, built at {}, {})", GROWBENCH_VERSION, c.commit,
                     c.dirty == "true" ? " with uncommitted changes" : "", GROWBENCH_GIT_COMMIT, GROWBENCH_BUILD_TYPE);
}

RunContext run_context_record() {
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof(date), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  RunContext c;
  const SourceCommit commit = source_commit();
  c.growbench_commit = commit.commit;
  c.commit_time = commit.time;
  c.dirty = commit.dirty;
  c.configured_commit = GROWBENCH_GIT_COMMIT;
  c.build_type = GROWBENCH_BUILD_TYPE;
  c.compiler = fmt::format("g++ {}", __VERSION__);
  c.cxx_flags = GROWBENCH_CXX_FLAGS;
  c.binary_hash = binary_hash();
  c.cpu_model = cpu_model();
  c.hardware_threads = std::thread::hardware_concurrency();
  c.date = date;
  c.alloc_counting = alloc_counting_enabled();
  c.load_average_start = load_average();
  c.cpu_mhz = cpu_mhz();
  c.cpu_governor = cpu_governor();
  c.plugins = loaded_plugins();
  c.dependencies = {{"embree", fmt::format("{}.{}.{}", RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH)},
                    {"openvdb", OPENVDB_LIBRARY_VERSION_STRING},
                    {"tbb", TBB_VERSION_STRING},
                    {"fmt", FMT_VERSION}};
  return c;
}

nlohmann::json run_context() {
  return to_json(run_context_record());
}

TrialSpec trial_spec_from_json(const nlohmann::json& j) {
  return from_json<TrialSpec>(j, "the trial spec");
}

TrialSpec read_trial_spec(const std::string& path) {
  return from_json<TrialSpec>(read_json_file(path), path);
}

namespace {

// The algorithm's effective parameters; InputError for bad input, before anything is loaded or grown.
Params checked_params(const TrialSpec& spec, const AlgorithmEntry& entry) {
  check_trial_spec(spec);
  Params params = default_params(entry);
  for (const auto& a : spec.params) params.set_assignment(a);
  if (spec.frame_every > 0 && spec.out_dir.empty()) throw InputError("--frames needs an output directory");
  return params;
}

// What a trial holds while it runs, kept to the end (see TrialSpec::skip_teardown).
struct TrialState {
  Scene scene;
  std::unique_ptr<SceneQuery> query;
  std::unique_ptr<GrowthAlgorithm> algo;
  std::optional<Plant> styled;  // the plant after the organ pass, when it ran
  OutputMesh mesh;
};

// The scene_load and query_build phases; the scene's seeds replaced by --seed-at, snapped to the surface.
// Scene load includes the algorithm's own input files (its load_inputs).
void load_scene_and_query(const TrialSpec& spec, const Params& params, TrialState& st, PhaseTimer& timer,
                          TrialRecord& rec) {
  st.scene = timer.run(Phase::scene_load, rec.phases, [&] {
    Scene scene = load_scene(spec.scene, spec.scene_params);
    st.algo->load_inputs(params);
    return scene;
  });
  SceneQueryOptions qo;
  qo.voxel_size = static_cast<float>(spec.voxel_size);
  if (spec.band_voxels > 0.0) qo.band_voxels = static_cast<float>(spec.band_voxels);
  st.query = timer.run(Phase::query_build, rec.phases, [&] { return std::make_unique<SceneQuery>(st.scene, qo); });
  PhaseMeasures& q = *rec.phases[Phase::query_build];
  q.bvh_s = st.query->bvh_build_seconds();
  q.sdf_s = st.query->sdf_build_seconds();
  q.sdf_active_voxels = st.query->sdf_active_voxels();
  q.voxel_size_m = st.query->voxel_size();
  if (!spec.seed_at.empty()) {
    st.scene.seeds.clear();
    for (const auto& a : spec.seed_at) {
      const glm::vec3 p(static_cast<float>(a[0]), static_cast<float>(a[1]), static_cast<float>(a[2]));
      const ClosestHit h = st.query->closest_point(p);
      st.scene.seeds.push_back({h.found ? h.point : p, {0, 1, 0}, 0});
    }
  }
  rec.scene = {
      spec.scene,       st.scene.name, st.scene.content_hash(), st.scene.triangle_count(), st.scene.seeds.size(),
      spec.scene_params};
}

// The algorithm's own files for `plant` (its plant as it is now), as `request` asks. Each decal's image
// must be among them: a render of the plant reads it from beside the snapshot that names it.
std::vector<OutputFile> algorithm_outputs(const GrowthAlgorithm& algo, const Plant& plant,
                                          const OutputRequest& request) {
  std::vector<OutputFile> files = algo.write_outputs(request);
  for (const auto& d : plant.decals) {
    const std::string want = request.prefix + d.image;
    if (std::none_of(files.begin(), files.end(), [&](const OutputFile& f) { return f.name == want; }))
      throw std::logic_error(fmt::format("algorithm '{}' wrote no {} for its decal (write_outputs into {})",
                                         algo.describe().name, want, request.dir));
  }
  return files;
}

// Frame capture (growth animations): OUT/frames/step_NNNNNN.gbplant, and the files its decals name
// (step_NNNNNN.IMAGE, from the algorithm's write_outputs), their cost measured to be taken out of the
// growth phase. It takes the algorithm, not its plant: some algorithms build their plant on demand, and
// that must not happen inside the growth phase unless a frame is kept.
struct FrameCapture {
  const TrialSpec& spec;
  int frames = 0, last_frame = -1;
  double wall_s = 0.0, cpu_s = 0.0;
  void capture(int step, const GrowthAlgorithm& algo) {
    if (spec.frame_every <= 0 || step == last_frame) return;
    const auto w0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    const std::filesystem::path d = std::filesystem::path(spec.out_dir) / "frames";
    if (frames == 0) {
      std::filesystem::remove_all(d);
      make_directories(d.string());
    }
    const Plant& plant = algo.plant();
    // The frame's prefix keeps its images apart from the other frames' and from the run's own.
    const std::string prefix = fmt::format("step_{:06d}.", step);
    algorithm_outputs(algo, plant, {d.string(), prefix, true});
    write_plant_snapshot((d / (prefix + "gbplant")).string(), plant, prefix);
    ++frames;
    last_frame = step;
    wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    cpu_s += cpu_seconds() - c0;
  }
};

// The growth phase: steps until the algorithm finishes or a limit stops it.
void grow(const TrialSpec& spec, const Params& params, TrialState& st, PhaseTimer& timer, TrialRecord& rec,
          const std::function<void(const Progress&)>& progress) {
  GrowthAlgorithm& algo = *st.algo;
  int steps = 0;
  std::string stopped_by = "finished";
  CurveSampler curve;
  FrameCapture frames{spec};
  timer.run(Phase::growth, rec.phases, [&] {
    inject_fault(spec.fault);
    // One deadline, from before start(), for the algorithm's cancelled() and for this loop: a plant the
    // algorithm was told to stop growing is recorded as stopped by the time limit, however long start() took.
    if (spec.time_limit_s > 0.0)
      algo.set_deadline(std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(spec.time_limit_s)));
    algo.start(st.scene, *st.query, params, spec.seed);
    const auto t0 = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    curve.add(0, algo.node_count(), algo.organ_count(), elapsed());
    while (true) {
      if (steps >= spec.max_steps) {
        stopped_by = "max_steps";
        break;
      }
      if (algo.cancelled()) {
        stopped_by = "time_limit";
        break;
      }
      if (spec.budget_nodes > 0 && algo.node_count() >= spec.budget_nodes) {
        stopped_by = "budget_nodes";
        break;
      }
      if (spec.budget_length_m > 0.0 && algo.plant().total_length() >= spec.budget_length_m) {
        stopped_by = "budget_length";
        break;
      }
      const bool more = algo.step();
      ++steps;
      const double t = elapsed();
      curve.add(steps, algo.node_count(), algo.organ_count(), t);
      if (progress) progress({steps, algo.node_count(), t});
      if (spec.frame_every > 0 && steps % spec.frame_every == 0 && more) frames.capture(steps, algo);
      if (!more) break;
    }
    algo.finish();
    frames.capture(steps, algo);
  });
  if (spec.frame_every > 0) {
    PhaseMeasures& g = *rec.phases[Phase::growth];
    g.wall_s -= frames.wall_s;
    g.cpu_s -= frames.cpu_s;
    g.frame_capture_wall_s = frames.wall_s;
    g.frame_capture_cpu_s = frames.cpu_s;
    rec.frames = FramesInfo{spec.frame_every, frames.frames, "frames"};
  }
  rec.results.steps = steps;
  rec.results.stopped_by = stopped_by;
  rec.results.curve = std::move(curve.curve);
}

// The meshing, export, outputs and metrics phases, then what the plant and its mesh hold.
void mesh_export_measure(const TrialSpec& spec, const MesherOptions& mesher, TrialState& st, PhaseTimer& timer,
                         TrialRecord& rec) {
  const Plant& plant = st.styled ? *st.styled : st.algo->plant();
  // The plant itself, for rendering later (`growbench render`); not an output format, not timed. Written
  // before the exports: after them, tens of MB of dirty pages can make the kernel throttle this write.
  if (!spec.out_dir.empty()) {
    make_directories(spec.out_dir);
    rec.snapshot_bytes = write_plant_snapshot((std::filesystem::path(spec.out_dir) / "plant.gbplant").string(), plant);
  }
  TrialResults& out = rec.results;
  st.mesh = timer.run(Phase::meshing, rec.phases, [&] { return mesh_plant(plant, mesher); });
  timer.run(Phase::exporting, rec.phases, [&] {
    if (spec.out_dir.empty()) return;
    make_directories(spec.out_dir);
    const std::filesystem::path d(spec.out_dir);
    OutputBytes& b = out.output_bytes;
    b.obj = write_obj((d / "plant.obj").string(), st.mesh);
    b.ply = write_ply((d / "plant.ply").string(), st.mesh);
    b.glb = write_glb((d / "plant.glb").string(), st.mesh, spec.glb, plant, organ_shapes(plant, mesher));
    b.glb_plain = spec.glb == GlbLayout::Plain ? *b.glb : plain_glb_bytes(st.mesh);
    b.skeleton_obj = write_skeleton_obj((d / "skeleton.obj").string(), plant);
    b.skeleton_ply = write_skeleton_ply((d / "skeleton.ply").string(), plant);
  });
  if (!spec.out_dir.empty()) {
    timer.run(Phase::outputs, rec.phases, [&] {
      for (const auto& f : algorithm_outputs(*st.algo, plant, {spec.out_dir, "", false}))
        out.output_bytes.algorithm_files[f.name] = f.bytes;
    });
    if (out.output_bytes.algorithm_files.empty()) rec.phases[Phase::outputs].reset();  // it wrote nothing
  }
  if (spec.metrics) {
    MetricOptions metric_options;
    metric_options.custom_leaf = mesher.leaf;
    out.metrics =
        timer.run(Phase::metrics, rec.phases, [&] { return compute_metrics(plant, *st.query, metric_options); });
  }
  std::size_t segments = 0;
  for (const auto& n : plant.nodes) segments += n.parent != kNoParent ? 1 : 0;
  out.counts = {plant.nodes.size(),      segments,
                plant.leaf_count(),      plant.organs.size(),
                plant.polygons.size(),   st.mesh.positions.size(),
                st.mesh.triangles.size()};
  out.total_length_m = plant.total_length();
  out.geometry_hash = plant.geometry_hash();
  for (const auto& [k, v] : st.algo->stats()) out.algorithm_stats[k] = v;
  out.verdict = judge_plant(plant, st.scene, out.metrics ? &*out.metrics : nullptr, st.algo->own_verdict());
}

// The organ pass (variation, then placement) on a copy of the grown plant, when an option asks for it.
void organ_pass(const TrialSpec& spec, const OrganOptions& options, const Params& given, const MesherOptions& mesher,
                TrialState& st, PhaseTimer& timer, TrialRecord& rec) {
  if (spec.organs.empty()) return;
  OrganPassRecord out;
  out.options = given.to_json();
  timer.run(Phase::organs, rec.phases, [&] {
    st.styled = st.algo->plant();
    vary_organs(*st.styled, options, spec.seed);
    const PlacementCounts c = place_organs(*st.styled, options, mesher.leaf.get());
    out.placed = c.placed;
    out.fallen_back = c.fallen_back;
    out.dropped = c.dropped;
    for (std::size_t k = 0; k < c.by_kind.size(); ++k) {
      const auto& n = c.by_kind[k];
      if (n.placed + n.fallen_back + n.dropped > 0)
        out.by_kind[to_string(static_cast<OrganKind>(k))] = {n.placed, n.fallen_back, n.dropped};
    }
  });
  rec.results.organs = std::move(out);
}

// What the algorithm's own input files set, and their hashes (a grammar's premise, not the default's), and
// what it warned of in its input.
void record_inputs(const GrowthAlgorithm& algo, TrialResults& r) {
  if (const auto effective = algo.effective_params()) r.params = effective->to_json();
  for (const auto& [param, path] : algo.input_files()) r.inputs.push_back({param, path, file_hash(path)});
  r.warnings = algo.warnings();
}

// A failed trial has no record to keep what the algorithm warned of in its input, and a warning (a '/30'
// read as '/', '3', '0') often explains the failure: the error carries them.
std::string with_warnings(const std::string& message, const std::vector<std::string>& warnings) {
  std::string out = message;
  for (const auto& w : warnings) out += "\n  warning: " + w;
  return out;
}

}  // namespace

TrialRecord run_trial_record(const TrialSpec& spec, const std::function<void(const Progress&)>& progress,
                             Plant* plant_out, Scene* scene_out) {
  load_plugins(spec.plugins);
  const AlgorithmEntry& entry = find_algorithm(spec.algorithm);
  const Params params = checked_params(spec, entry);
  // A custom leaf is read first: a bad file is invalid input before anything is grown.
  MesherOptions mesher_options;
  mesher_options.sides = spec.sides;
  mesher_options.leaf_obj = spec.leaf_obj;
  const MesherOptions mesher = with_leaf_mesh(mesher_options);
  Params organ_params;
  const OrganOptions organ_options = read_organ_options(spec.organs, &organ_params);
  std::unique_ptr<tbb::global_control> threads;
  if (spec.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<std::size_t>(spec.threads));

  const auto load_at_start = load_average();
  TrialRecord rec;
  rec.algorithm = spec.algorithm;
  rec.seed = spec.seed;
  rec.max_steps = spec.max_steps;
  rec.spec = spec;
  rec.results.threads = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  PhaseTimer timer;
  TrialState st;
  st.algo = entry.make();
  load_scene_and_query(spec, params, st, timer, rec);
  rec.results.params = params.to_json();
  if (!spec.leaf_obj.empty()) rec.leaf_obj = spec.leaf_obj;

  try {
    grow(spec, params, st, timer, rec, progress);
  } catch (const InputError& e) {
    throw InputError(with_warnings(e.what(), st.algo->warnings()));
  }
  record_inputs(*st.algo, rec.results);
  const Plant& plant = st.algo->plant();
  // An algorithm whose input can draw an invalid plant (an L-system's grammar is a program) refuses it in
  // finish(), as bad input; a plugin's invalid plant is the plugin's error; a built-in's is a bug.
  if (const std::string bad = plant.validate(); !bad.empty()) {
    if (entry.plugin)
      throw PluginError(fmt::format("algorithm '{}' (plugin {}) handed over an invalid plant: {}", spec.algorithm,
                                    entry.plugin->path, bad));
    throw std::logic_error(fmt::format("algorithm '{}' produced an invalid plant: {}", spec.algorithm, bad));
  }
  organ_pass(spec, organ_options, organ_params, mesher, st, timer, rec);
  if (plant_out) *plant_out = st.styled ? *st.styled : plant;
  mesh_export_measure(spec, mesher, st, timer, rec);

  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  rec.peak_rss_bytes = static_cast<std::uint64_t>(ru.ru_maxrss) * 1024u;  // whole process, never reset
  rec.status = "ok";
  if (spec.context) {
    rec.context = run_context_record();
    rec.context->load_average_end = rec.context->load_average_start;
    rec.context->load_average_start = load_at_start;
  }

  if (!spec.out_dir.empty()) {
    const std::string path = (std::filesystem::path(spec.out_dir) / "record.json").string();
    // Indented for people reading `growbench run` output; compact when a suite parent parses it.
    write_file_atomic(path, json_text(to_json(rec), spec.skip_teardown ? -1 : 2));
  }
  // Copied, not moved: the algorithm, destroyed last, may still point into the trial's scene. After the
  // peak RSS is read, so that the copy is not counted in the record.
  if (scene_out) *scene_out = st.scene;
  // Deliberately never freed: the process exits next and the kernel reclaims it all at once. Held by a
  // static, so that a leak checker sees it still reachable at exit.
  if (spec.skip_teardown) {
    [[maybe_unused]] static TrialState* kept = nullptr;
    kept = new TrialState{std::move(st)};
  }
  return rec;
}

nlohmann::json run_trial(const TrialSpec& spec, const std::function<void(const Progress&)>& progress,
                         Plant* plant_out) {
  return to_json(run_trial_record(spec, progress, plant_out));
}

}  // namespace growbench
