#include "harness/record/files.hpp"
#include "harness/suite/suite.hpp"

#include <signal.h>
#include <unistd.h>

#include <sys/statvfs.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <log4cplus/config.hxx>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <xxhash.h>

#include "algorithms/algorithm.hpp"
#include "algorithms/plugins/loader.hpp"
#include "core/errors.hpp"
#include "core/json_util.hpp"
#include "core/utf8.hpp"
#include "harness/organs/options.hpp"
#include "harness/output/exporters.hpp"
#include "harness/record/record.hpp"
#include "harness/run/ordered_pool.hpp"
#include "harness/run/process.hpp"
#include "harness/run/trial.hpp"
#include "harness/stats/stats.hpp"
#include "scenes/scene_library.hpp"

namespace growbench {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string read_text(const std::string& path) {
  return read_input_file(path);
}

// A trial's message (error.txt) as a sample records it: a plugin's failure can be any size (a 64 MiB one
// was copied into results.json whole), so at most kMaxMessageBytes of it, the cut said.
constexpr std::size_t kMaxMessageBytes = 4096;
std::string read_message(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(kMaxMessageBytes + 1, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.size() <= kMaxMessageBytes) return head;
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  return fmt::format("{} (cut: the message has {} bytes; the whole is in {})", utf8_excerpt(head, kMaxMessageBytes),
                     ec ? 0 : size, path.string());
}

// How many processes the kernel's OOM killer has ended in this process's cgroup (cgroup v2), if it says.
std::optional<std::uint64_t> oom_kills() {
  std::ifstream cg("/proc/self/cgroup");
  std::string line, path;
  while (std::getline(cg, line))
    if (line.rfind("0::", 0) == 0) path = line.substr(3);
  if (path.empty()) return std::nullopt;
  std::ifstream events("/sys/fs/cgroup" + path + "/memory.events");
  std::string key;
  std::uint64_t n = 0;
  while (events >> key >> n)
    if (key == "oom_kill") return n;
  return std::nullopt;
}

void write_atomic(const fs::path& path, const std::string& text) {
  write_file_atomic(path.string(), text.data(), text.size());
}

std::string value_text(const json& v) {
  return v.is_string() ? v.get<std::string>() : v.dump();
}

class SuiteReader : public JsonPathReader {
 public:
  explicit SuiteReader(const std::string& file) : JsonPathReader(file), dir_(fs::path(file).parent_path()) {}
  double number(const json& j, const std::string& path, double lo, double hi) const {
    if (!j.is_number() || j.get<double>() < lo || j.get<double>() > hi)
      fail(path, fmt::format("expected a number in [{}, {}], got {}", lo, hi, json_text(j, -1).substr(0, 80)));
    return j.get<double>();
  }
  // The string at j[key] (j an object), or `fallback` when absent; `what` says what it is, for errors.
  std::string string_field(const json& j, const std::string& path, const char* key, const std::string& fallback,
                           const char* what) const {
    if (!j.contains(key)) return fallback;
    if (!j[key].is_string())
      fail(fmt::format("{}/{}", path, key), fmt::format("expected {}, got {}", what, j[key].type_name()));
    return j[key].get<std::string>();
  }
  // A name (the suite's, a scene's, an entry's label): it becomes folders, file names and captions.
  std::string name_field(const json& j, const std::string& path, const char* key, const std::string& fallback,
                         const char* what) const {
    std::string s = string_field(j, path, key, fallback, what);
    if (const std::string bad = name_problem(s); !bad.empty() && j.contains(key))
      fail(fmt::format("{}/{}", path, key), bad);
    return s;
  }
  // A path in a suite file, relative to the suite file.
  std::string relative_to_suite(const std::string& path) const {
    const fs::path p(path);
    return (p.is_absolute() ? p : dir_ / p).lexically_normal().string();
  }
  // Scene specs in suites: mesh:PATH and *.json are relative to the suite file (mesh:NAME is a bundled mesh).
  std::string scene_spec(const std::string& spec) const {
    if (spec.rfind("mesh:", 0) == 0 && !is_mesh_name(spec.substr(5)))
      return "mesh:" + relative_to_suite(spec.substr(5));
    if (spec.size() > 5 && spec.substr(spec.size() - 5) == ".json") return relative_to_suite(spec);
    return spec;
  }

  Suite read() const {
    const std::string text = read_text(file());
    const json j = parse_input_json(file(), text);
    std::vector<std::string> keys = {"schema_version", "name",      "description",     "repetitions",
                                     "warmup",         "timeout_s", "memory_limit_mb", "seeds",
                                     "budget",         "scenes",    "algorithms",      "plugins"};
    keys.insert(keys.end(), kSettings.begin(), kSettings.end());
    only_keys(j, "", keys);
    if (!j.contains("schema_version") || j["schema_version"] != 1) fail("/schema_version", "expected 1");
    Suite s;
    s.file = file();
    s.hash = fmt::format("{:016x}", XXH3_64bits(text.data(), text.size()));
    const Common common = read_settings(j, s);
    const std::vector<SceneEntry> scenes = read_scenes(j);
    load_listed_plugins(j);
    const std::vector<AlgoEntry> algos = read_algorithms(j, common);
    make_cells(common, scenes, algos, s);
    return s;
  }

 private:
  // The trial settings a suite file may give, at its top level for every cell or in an algorithm entry for
  // its own: the trial spec's fields of the same names, checked as the spec declares them.
  static constexpr std::array<const char*, 10> kSettings = {
      "threads", "max_steps",    "time_limit_s",    "voxel_size", "band_voxels",
      "sides",   "budget_nodes", "budget_length_m", "metrics",    "glb"};

  // What every cell shares, from the top level of the file.
  struct Common {
    TrialSpec spec;  // its settings
    std::vector<std::uint64_t> seeds = {1};
    double timeout_s = 0.0;  // the suite's
  };
  struct SceneEntry {
    std::string spec, name;
    std::vector<std::string> params;
  };
  struct AlgoEntry {
    std::string label, name;
    TrialSpec spec;  // the common settings, with the entry's own (fault, leaf_obj, organs, settings)
    std::vector<std::string> params;
    std::vector<std::pair<std::string, std::vector<json>>> sweep;
    std::vector<json> points;  // explicit sweep points (instead of a product)
    // Its sweep points, saturating at kMaxSuiteCells + 1 (a product of sweeps can overflow).
    [[nodiscard]] std::size_t count() const {
      if (!points.empty()) return points.size();
      std::size_t n = 1;
      for (const auto& [k, v] : sweep) n = std::min(n * v.size(), kMaxSuiteCells + 1);  // n stays small: no overflow
      return n;
    }
  };

  // "plugins": files relative to the suite file, loaded before its algorithms are looked up.
  void load_listed_plugins(const json& j) const {
    if (!j.contains("plugins")) return;
    if (!j["plugins"].is_array()) fail("/plugins", "expected an array of plugin files");
    for (std::size_t i = 0; i < j["plugins"].size(); ++i) {
      const std::string path = fmt::format("/plugins/{}", i);
      if (!j["plugins"][i].is_string()) fail(path, "expected a plugin file's path");
      try {
        load_plugin(relative_to_suite(j["plugins"][i].get<std::string>()));
      } catch (const InputError& e) {
        fail(path, e.what());
      }
    }
  }

  Common read_settings(const json& j, Suite& s) const {
    s.name = name_field(j, "", "name", fs::path(file()).stem().string(), "the suite's name");
    s.description = string_field(j, "", "description", "", "a description");
    if (j.contains("repetitions")) s.repetitions = static_cast<int>(number(j["repetitions"], "/repetitions", 1, 1000));
    if (j.contains("warmup")) s.warmup = static_cast<int>(number(j["warmup"], "/warmup", 0, 100));
    if (j.contains("timeout_s")) s.timeout_s = number(j["timeout_s"], "/timeout_s", 0.001, 1e6);
    if (j.contains("memory_limit_mb"))
      s.memory_limit_bytes = static_cast<std::uint64_t>(number(j["memory_limit_mb"], "/memory_limit_mb", 64, 1e7))
                             << 20;
    Common c;
    c.timeout_s = s.timeout_s;
    read_settings_into(j, "", c.spec);
    check_time_limit(c.spec, "", c.timeout_s);
    if (j.contains("seeds")) {
      if (!j["seeds"].is_array() || j["seeds"].empty()) fail("/seeds", "expected a non-empty array of seeds");
      c.seeds.clear();
      for (std::size_t i = 0; i < j["seeds"].size(); ++i) {
        read_spec_field(c.spec, "seed", j["seeds"][i], file(), fmt::format("/seeds/{}", i));
        c.seeds.push_back(c.spec.seed);
      }
    }
    if (j.contains("budget")) {  // the older spelling of budget_nodes and budget_length_m
      only_keys(j["budget"], "/budget", {"nodes", "length_m"});
      if (j["budget"].contains("nodes"))
        read_spec_field(c.spec, "budget_nodes", j["budget"]["nodes"], file(), "/budget/nodes");
      if (j["budget"].contains("length_m"))
        read_spec_field(c.spec, "budget_length_m", j["budget"]["length_m"], file(), "/budget/length_m");
    }
    return c;
  }

  // The settings `j` gives (kSettings), into `spec`.
  void read_settings_into(const json& j, const std::string& path, TrialSpec& spec) const {
    for (const char* key : kSettings)
      if (j.contains(key)) read_spec_field(spec, key, j[key], file(), fmt::format("{}/{}", path, key));
  }

  // time_limit_s is what drives an algorithm's cancellation (host->cancelled() for a plugin): it stops growth
  // and keeps the plant. timeout_s kills the trial's process and loses it, so a limit at or past the timeout
  // would never be reached.
  void check_time_limit(const TrialSpec& spec, const std::string& path, double timeout_s) const {
    if (spec.time_limit_s > 0.0 && spec.time_limit_s >= timeout_s)
      fail(path + "/time_limit_s",
           fmt::format("{} s is not under the suite's timeout_s ({} s): the trial would be killed, and its plant lost, "
                       "before the time limit stops growth",
                       spec.time_limit_s, timeout_s));
  }

  std::vector<SceneEntry> read_scenes(const json& j) const {
    std::vector<SceneEntry> scenes;
    if (!j.contains("scenes") || !j["scenes"].is_array() || j["scenes"].empty())
      fail("/scenes", "expected a non-empty array of scenes");
    for (std::size_t i = 0; i < j["scenes"].size(); ++i) {
      const auto& e = j["scenes"][i];
      const std::string path = fmt::format("/scenes/{}", i);
      SceneEntry se;
      if (e.is_string()) {
        se.spec = scene_spec(e.get<std::string>());
      } else {
        only_keys(e, path, {"scene", "params", "name"});
        if (!e.contains("scene") || !e["scene"].is_string()) fail(path + "/scene", "expected the scene's name or path");
        se.spec = scene_spec(e["scene"].get<std::string>());
        if (e.contains("params")) {
          if (!e["params"].is_object()) fail(path + "/params", "expected an object of scene parameters");
          for (const auto& [k, v] : e["params"].items()) se.params.push_back(k + "=" + value_text(v));
        }
        se.name = name_field(e, path, "name", "", "the scene's display name");
      }
      try {
        const Scene sc = load_scene(se.spec, se.params);
        if (se.name.empty()) se.name = sc.name;
      } catch (const InputError& err) {
        fail(path, err.what());
      }
      scenes.push_back(std::move(se));
    }
    return scenes;
  }

  std::vector<AlgoEntry> read_algorithms(const json& j, const Common& common) const {
    std::vector<AlgoEntry> algos;
    if (!j.contains("algorithms") || !j["algorithms"].is_array() || j["algorithms"].empty())
      fail("/algorithms", "expected a non-empty array of algorithm entries");
    std::set<std::string> labels;
    for (std::size_t i = 0; i < j["algorithms"].size(); ++i) {
      algos.push_back(read_algorithm(j["algorithms"][i], fmt::format("/algorithms/{}", i), common, labels));
    }
    return algos;
  }

  // One entry of "algorithms"; its label must not be in `labels` (the entries before it), and is added.
  AlgoEntry read_algorithm(const json& e, const std::string& path, const Common& common,
                           std::set<std::string>& labels) const {
    AlgoEntry a;
    a.spec = common.spec;
    if (e.is_string()) {
      a.name = e.get<std::string>();
    } else {
      std::vector<std::string> keys = {"name", "label", "params", "sweep", "fault", "leaf_obj", "organs"};
      keys.insert(keys.end(), kSettings.begin(), kSettings.end());
      only_keys(e, path, keys);
      if (!e.contains("name") || !e["name"].is_string()) fail(path + "/name", "expected the algorithm's name");
      a.name = e["name"].get<std::string>();
      a.label = name_field(e, path, "label", "", "the entry's label");
      read_settings_into(e, path, a.spec);
      check_time_limit(a.spec, path, common.timeout_s);
      if (e.contains("fault")) {
        read_spec_field(a.spec, "fault", e["fault"], file(), path + "/fault");
        if (const std::string bad = fault_problem(a.spec.fault); !bad.empty()) fail(path + "/fault", bad);
      }
      if (e.contains("leaf_obj")) {
        if (!e["leaf_obj"].is_string()) fail(path + "/leaf_obj", "expected the path of an OBJ file");
        a.spec.leaf_obj = relative_to_suite(e["leaf_obj"].get<std::string>());
        try {
          (void)load_organ_obj(a.spec.leaf_obj);
        } catch (const InputError& err) {
          fail(path + "/leaf_obj", err.what());
        }
      }
      if (e.contains("organs")) read_organs(e["organs"], path + "/organs", a);
    }
    const AlgorithmEntry* entry = nullptr;
    try {
      entry = &find_algorithm(a.name);
    } catch (const InputError& err) {
      fail(path + "/name", err.what());
    }
    if (a.label.empty()) a.label = a.name;
    if (!labels.insert(a.label).second)
      fail(path + "/label", fmt::format("label '{}' is used twice; give each entry its own", a.label));
    Params p = default_params(*entry);
    if (e.is_object() && e.contains("params")) {
      if (!e["params"].is_object()) fail(path + "/params", "expected an object of parameters");
      for (const auto& [k, v] : e["params"].items()) {
        try {
          p.set_json(k, v);
        } catch (const InputError& err) {
          fail(path + "/params/" + k, err.what());
        }
        a.params.push_back(k + "=" + value_text(v));
      }
    }
    if (e.is_object() && e.contains("sweep")) read_sweep(e["sweep"], path, p, a);
    return a;
  }

  // The organ options, checked now as every other input is.
  void read_organs(const json& o, const std::string& path, AlgoEntry& a) const {
    if (!o.is_object()) fail(path, "expected an object of organ options (see `growbench list`)");
    Params p("organ options", organ_param_specs());
    for (const auto& [k, v] : o.items()) {
      try {
        p.set_json(k, v);
      } catch (const InputError& err) {
        fail(path + "/" + k, err.what());
      }
      a.spec.organs.push_back(k + "=" + value_text(v));
    }
    try {
      (void)read_organ_options(a.spec.organs);
    } catch (const InputError& err) {
      fail(path, err.what());
    }
  }

  // Every swept value is checked against the entry's parameters `p`.
  void read_sweep(const json& sw, const std::string& path, const Params& p, AlgoEntry& a) const {
    if (sw.is_object()) {  // parameter -> values: the cartesian product
      for (const auto& [k, vals] : sw.items()) {
        if (!vals.is_array() || vals.empty()) fail(path + "/sweep/" + k, "expected a non-empty array of values");
        for (std::size_t v = 0; v < vals.size(); ++v) {
          try {
            Params q = p;
            q.set_json(k, vals[v]);
          } catch (const InputError& err) {
            fail(fmt::format("{}/sweep/{}/{}", path, k, v), err.what());
          }
        }
        a.sweep.emplace_back(k, std::vector<json>(vals.begin(), vals.end()));
      }
    } else if (sw.is_array() && !sw.empty()) {  // an explicit list of points: {parameter: value, ...}
      for (std::size_t v = 0; v < sw.size(); ++v) {
        const std::string pp = fmt::format("{}/sweep/{}", path, v);
        if (!sw[v].is_object() || sw[v].empty()) fail(pp, "expected an object of parameter values");
        Params q = p;
        for (const auto& [k, val] : sw[v].items()) {
          try {
            q.set_json(k, val);
          } catch (const InputError& err) {
            fail(pp + "/" + k, err.what());
          }
        }
        a.points.push_back(sw[v]);
      }
    } else {
      fail(path + "/sweep", "expected an object (parameter -> array of values) or an array of parameter objects");
    }
  }

  // Cells. Order: for each scene, seed and sweep point, every algorithm entry in turn (interleaved).
  void make_cells(const Common& common, const std::vector<SceneEntry>& scenes, const std::vector<AlgoEntry>& algos,
                  Suite& s) const {
    std::size_t max_points = 1, points = 0;
    for (const auto& a : algos) {
      max_points = std::max(max_points, a.count());
      points = std::min(points + a.count(), kMaxSuiteCells + 1);
    }
    // Refused before a cell is made: a matrix of a billion cells would exhaust memory before its first trial.
    const double cells =
        static_cast<double>(scenes.size()) * static_cast<double>(common.seeds.size()) * static_cast<double>(points);
    if (cells > static_cast<double>(kMaxSuiteCells))
      fail("", fmt::format(
                   "the suite makes {} cells (scenes x seeds x the sweep points of every algorithm entry); "
                   "a suite may have at most {}: split it into several suites, or sweep fewer values",
                   points > kMaxSuiteCells ? fmt::format("more than {}", kMaxSuiteCells) : fmt::format("{:.0f}", cells),
                   kMaxSuiteCells));
    std::set<std::string> ids;
    for (const auto& sc : scenes)
      for (const auto seed : common.seeds)
        for (std::size_t point = 0; point < max_points; ++point)
          for (const auto& a : algos) {
            if (point >= a.count()) continue;
            SuiteConfig c;
            c.label = a.label;
            c.scene_name = sc.name;
            c.spec = a.spec;
            c.spec.algorithm = a.name;
            c.spec.scene = sc.spec;
            c.spec.scene_params = sc.params;
            c.spec.params = a.params;
            c.spec.seed = seed;
            std::size_t rest = point;
            std::vector<std::string> parts;
            auto assign = [&](const std::string& k, const json& val) {
              c.sweep[k] = val;
              c.spec.params.push_back(k + "=" + value_text(val));
              parts.push_back(k + "=" + value_text(val));
            };
            if (!a.points.empty()) {
              for (const auto& [k, val] : a.points[point].items()) assign(k, val);
            } else {
              for (const auto& [k, v] : a.sweep) {
                assign(k, v[rest % v.size()]);
                rest /= v.size();
              }
            }
            c.id = fmt::format("{}/{}/s{}{}{}", safe_name(a.label), safe_name(sc.name), seed, parts.empty() ? "" : "/",
                               safe_name(fmt::format("{}", fmt::join(parts, ","))));
            if (!ids.insert(c.id).second)
              fail("/scenes", fmt::format("two cells share the id '{}' (give the scenes distinct 'name's)", c.id));
            s.configs.push_back(std::move(c));
          }
  }

  fs::path dir_;
};

// Under callgrind a trial runs this many times slower; its timeout grows with it.
constexpr double kCallgrindSlowdown = 60.0;

// The per-phase instruction counts of a trial run under callgrind: every CALLGRIND_DUMP_STATS_AT(phase)
// wrote DIR/callgrind.out.N with "desc: Trigger: Client Request: PHASE" and "totals: IR". The files are
// removed once read (the final dump at program exit is not a phase).
InstructionCounts read_callgrind_phases(const fs::path& dir) {
  InstructionCounts out;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind("callgrind.out", 0) == 0) files.push_back(e.path());
  for (const auto& f : files) {
    std::ifstream in(f);
    std::string line, phase;
    std::uint64_t ir = 0;
    bool have = false;
    const std::string trigger = "desc: Trigger: Client Request: ";
    while (std::getline(in, line)) {
      if (line.rfind(trigger, 0) == 0) phase = line.substr(trigger.size());
      if (line.rfind("totals:", 0) == 0 || line.rfind("summary:", 0) == 0) {
        ir = std::stoull(line.substr(line.find(':') + 1));
        have = true;
      }
    }
    if (const auto p = phase_named(phase); p && have) out[*p] = ir;
    fs::remove(f);
  }
  return out;
}

// A cell's results from its first successful repetition's record.
CellResults cell_results_of(const TrialRecord& rec, const std::optional<InstructionCounts>& instructions) {
  CellResults c;
  c.plant = rec.results;
  c.scene_hash = rec.scene.hash;
  AllocByPhase& alloc = c.alloc.emplace();
  rec.phases.each([&](Phase p, const PhaseMeasures& m) { alloc[p] = AllocCount{m.alloc_count, m.alloc_bytes}; });
  c.instructions = instructions;
  return c;
}

// The growth phase's wall time of every ok repetition of a cell, in repetition order.
std::vector<double> growth_times(const SuiteCell& t) {
  std::vector<double> v;
  for (const auto& s : t.samples)
    if (const PhaseMeasures* g = s.status == "ok" && s.phases ? s.phases->find(Phase::growth) : nullptr)
      v.push_back(g->wall_s);
  return v;
}

MedianSummary median_summary(const std::vector<double>& v) {
  MedianSummary m;
  m.n = v.size();
  m.median = median_of(v);
  const auto [lo, hi] = median_interval(v, m.exact);
  m.lo = lo;
  m.hi = hi;
  return m;
}

// Adds one finished repetition to its cell: the live run and the journal replay both come here.
void apply_sample(SuiteCell& t, const SuiteSample& sample, const std::optional<CellResults>& cell) {
  if (sample.status == "ok") {
    // The plant this repetition grew (a journal written before samples kept it: its cell's).
    const std::string* grown = sample.geometry_hash  ? &*sample.geometry_hash
                               : cell && cell->plant ? &cell->plant->geometry_hash
                                                     : nullptr;
    if (!t.results.plant) {
      if (cell) take_present(t.results, *cell);
    } else if (grown && *grown != t.results.plant->geometry_hash) {
      t.nondeterministic = true;  // the same cell grew a different plant: report it loudly
    }
  }
  t.samples.push_back(sample);
  std::string st = "ok";
  for (const auto& s : t.samples)
    if (s.status != "ok") st = s.status;
  t.status = st;
  if (st != "ok")
    for (const auto& s : t.samples)
      if (s.status != "ok" && s.message) t.message = s.message;
}

// The growth time over the seeds of each algorithm entry (and sweep point) on each scene: every ok cell's
// ok repetitions pooled, as the report's table shows them. A plant judged degenerate or not applicable
// stands for nothing across cells, and is left out.
ResultsSummary results_summary(const std::vector<SuiteCell>& trials) {
  ResultsSummary out;
  std::vector<std::vector<double>> times;
  for (const auto& t : trials) {
    const std::vector<double> growth = growth_times(t);
    const auto& plant = t.results.plant;
    if (t.status != "ok" || growth.empty() || (plant && plant->verdict && !plant->verdict->valid())) continue;
    std::size_t g = 0;
    while (g < out.growth_s_over_seeds.size() &&
           !(out.growth_s_over_seeds[g].label == t.label && out.growth_s_over_seeds[g].scene == t.scene &&
             out.growth_s_over_seeds[g].sweep == t.sweep))
      ++g;
    if (g == out.growth_s_over_seeds.size()) {
      out.growth_s_over_seeds.push_back({t.label, t.scene, t.sweep, {}, {}});
      times.emplace_back();
    }
    out.growth_s_over_seeds[g].cells.push_back(t.id);
    times[g].insert(times[g].end(), growth.begin(), growth.end());
  }
  for (std::size_t g = 0; g < times.size(); ++g) out.growth_s_over_seeds[g].growth_s = median_summary(times[g]);
  return out;
}

// The growth time's median and interval of every cell, and over each entry's seeds, so that reports read
// them instead of computing them again. From the samples, whatever an earlier (resumed) file held.
void update_summaries(ResultsFile& results) {
  for (auto& t : results.trials) {
    const std::vector<double> growth = growth_times(t);
    if (growth.empty())
      t.summary.reset();
    else
      t.summary = CellSummary{median_summary(growth)};
  }
  results.summary = results_summary(results.trials);
}

// results.json as written: its summaries brought up to date first.
std::string results_text(ResultsFile& results) {
  update_summaries(results);
  return json_text(to_json(results), 1);
}

}  // namespace

Suite load_suite(const std::string& path) {
  if (const std::string why = file_problem(path, true); !why.empty())
    throw InputError(fmt::format("{}: {} (expected a suite file)", path, why));
  return SuiteReader(path).read();
}

SuitePlan plan_of(const Suite& suite) {
  std::set<std::string> entries, scenes, points;
  std::set<std::uint64_t> seeds;
  for (const auto& c : suite.configs) {
    entries.insert(c.label);
    scenes.insert(c.scene_name);
    seeds.insert(c.spec.seed);
    points.insert(c.label + '\n' + c.sweep.dump());
  }
  SuitePlan p;
  p.cells = suite.configs.size();
  p.entries = entries.size();
  p.scenes = scenes.size();
  p.seeds = seeds.size();
  p.sweep_points = points.size();
  p.repetitions = suite.repetitions;
  p.warmup = suite.warmup;
  p.trials = p.cells * static_cast<std::size_t>(suite.repetitions) + static_cast<std::size_t>(suite.warmup);
  return p;
}

std::string plan_text(const Suite& suite) {
  const SuitePlan p = plan_of(suite);
  const std::string points =
      p.sweep_points > p.entries ? fmt::format(", {} sweep points over the entries", p.sweep_points) : "";
  std::string out = fmt::format(
      "{}: {} cells ({} algorithm entries x {} scenes x {} seeds{}), {} repetition{} each and {} warm-up{}: {} "
      "trials\n",
      suite.name, p.cells, p.entries, p.scenes, p.seeds, points, p.repetitions, p.repetitions == 1 ? "" : "s", p.warmup,
      p.warmup == 1 ? "" : "s", p.trials);
  for (const auto& c : suite.configs) out += c.id + "\n";
  return out;
}

namespace {

// What a shard's context must share with the others for their timings to be compared: the machine type
// and the binary (its content hash, not the source tree's commit, which may move while shards run).
// Host names and dates may differ. Each as its name and its value as the JSON shows it.
std::vector<std::pair<const char*, std::string>> machine_keys(const RunContext& c) {
  return {{"cpu_model", json(c.cpu_model).dump()},
          {"hardware_threads", json(c.hardware_threads).dump()},
          {"binary_hash", json(c.binary_hash).dump()}};
}

// Which argument holds each shard (index -> argument); InputError for shards that do not fit together.
std::vector<std::size_t> shard_slots(const std::vector<ResultsFile>& shards, const std::vector<std::string>& names) {
  const ResultsFile& first = shards.front();
  const int count = first.shard.count;
  if (count < 1) throw InputError(fmt::format("{}: shard count {} (expected at least 1)", names[0], count));
  std::vector<std::size_t> slot(static_cast<std::size_t>(std::max(count, 1)), shards.size());
  for (std::size_t k = 0; k < shards.size(); ++k) {
    const ResultsFile& s = shards[k];
    if (s.kind != kResultsKind) throw InputError(fmt::format("{}: not a growbench results file", names[k]));
    if (s.suite_hash != first.suite_hash)
      throw InputError(fmt::format("{}: a shard of another suite (suite_hash {} vs {} in {})", names[k], s.suite_hash,
                                   first.suite_hash, names[0]));
    if (s.repetitions != first.repetitions)
      throw InputError(
          fmt::format("{}: {} repetitions, but {} has {}", names[k], s.repetitions, names[0], first.repetitions));
    if (s.mode != first.mode)
      throw InputError(fmt::format("{}: mode '{}' differs from {}'s", names[k], s.mode, names[0]));
    const int n = s.shard.count, i = s.shard.index;
    if (n != count)
      throw InputError(fmt::format("{}: shard of {} but {} is a shard of {}", names[k], n, names[0], count));
    if (i < 0 || i >= n) throw InputError(fmt::format("{}: shard index {} outside 0..{}", names[k], i, n - 1));
    if (slot[static_cast<std::size_t>(i)] != shards.size())
      throw InputError(fmt::format("{}: shard {}/{} given twice", names[k], i, n));
    slot[static_cast<std::size_t>(i)] = k;
  }
  return slot;
}

}  // namespace

ResultsFile merge_results(const std::vector<ResultsFile>& shards, const std::vector<std::string>& names,
                          bool mixed_machines) {
  if (shards.empty()) throw InputError("merge: no shard results given");
  const std::vector<std::size_t> slot = shard_slots(shards, names);
  const ResultsFile& first = shards.front();
  const int count = first.shard.count;
  std::vector<std::string> differ;
  const auto keys0 = machine_keys(first.context);
  for (std::size_t k = 1; k < shards.size(); ++k) {
    const auto keys = machine_keys(shards[k].context);
    for (std::size_t m = 0; m < keys.size(); ++m)
      if (keys[m].second != keys0[m].second)
        differ.push_back(
            fmt::format("{} {} in {} vs {} in {}", keys[m].first, keys[m].second, names[k], keys0[m].second, names[0]));
  }
  if (!differ.empty() && !mixed_machines)
    throw InputError(
        fmt::format("merge: the shards ran on different machines or builds, so their timings cannot be compared "
                    "({}); run every shard on identical nodes, or pass --mixed-machines to merge them marked as mixed",
                    fmt::join(differ, "; ")));
  for (int i = 0; i < count; ++i)
    if (slot[static_cast<std::size_t>(i)] == shards.size())
      throw InputError(fmt::format("merge: shard {}/{} is missing", i, count));
  // Cell k of the suite ran in shard k % count, as its (k / count)-th cell.
  ResultsFile merged = first;
  merged.shard = {0, 1};
  merged.trials.clear();
  merged.shards.emplace();
  std::size_t total = 0;
  for (int i = 0; i < count; ++i) {
    const std::size_t a = slot[static_cast<std::size_t>(i)];
    merged.shards->push_back({i, names[a], shards[a].context});
    total += shards[a].trials.size();
  }
  // Of a suite of `total` cells, shard i holds ceil((total - i) / count).
  const auto n = static_cast<std::size_t>(count);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = slot[i], has = shards[a].trials.size(), given = (total - std::min(total, i) + n - 1) / n;
    if (has != given)
      throw InputError(fmt::format("{}: shard {}/{} has {} cells, but a suite of {} cells in {} shards gives it {}",
                                   names[a], i, count, has, total, count, given));
  }
  std::set<std::string> ids;
  for (std::size_t k = 0; k < total; ++k) {
    const SuiteCell& cell = shards[slot[k % n]].trials[k / n];
    if (!ids.insert(cell.id).second)
      throw InputError(fmt::format("{}: cell '{}' is in the merged results twice; expected each cell in one shard",
                                   names[slot[k % n]], cell.id));
    merged.trials.push_back(cell);
  }
  if (!differ.empty()) merged.context.mixed_machines = true;
  merged.renders.reset();  // per-shard render summaries do not describe the merged grid
  merged.scenes.reset();   // every shard's scene files (one hash, one scene, whichever shard wrote it)
  for (const ResultsFile& s : shards) {
    if (!s.scenes) continue;
    if (!merged.scenes) merged.scenes.emplace();
    for (const auto& [hash, file] : *s.scenes) merged.scenes->try_emplace(hash, file);
  }
  update_summaries(merged);  // the seeds of one entry and scene may have run in different shards
  return merged;
}

json merge_results(const std::vector<json>& shards, const std::vector<std::string>& names, bool mixed_machines) {
  std::vector<ResultsFile> typed;
  for (std::size_t k = 0; k < shards.size(); ++k) {
    // A file without its shard would be read as shard 0 of 1: which part of the suite it holds is unknown.
    if (!shards[k].is_object() || !shards[k].contains("shard"))
      throw InputError(
          fmt::format("{}: no 'shard' key, so which shard of its suite it holds is unknown; expected "
                      "the results of `growbench suite --shard I/N`",
                      names.at(k)));
    typed.push_back(results_from_json(shards[k], names.at(k)));
  }
  return to_json(merge_results(typed, names, mixed_machines));
}

Outcome run_trial_child(const TrialSpec& spec, const std::string& dir_name, int report_fd) {
  const fs::path dir(dir_name);
  auto write_error = [&](const std::string& msg) {
    try {
      write_file_atomic((dir / "error.txt").string(), msg);
    } catch (const std::exception& e) {  // the suite then reports the exit status alone; the log keeps both
      fmt::print(stderr, "{}\n{}\n", msg, e.what());
    }
  };
  const auto started = std::chrono::steady_clock::now();
  const std::string oom = "out of memory (allocation refused under the address-space limit)";
  // A library's noexcept code, or its threads.
  exit_on_escaped_bad_alloc(trial_exit_code(Outcome::out_of_memory), oom, (dir / "error.txt").string());
  try {
    run_trial(spec);
    if (report_fd >= 0) {
      // steady_clock is CLOCK_MONOTONIC, comparable with the parent's clock; integer nanoseconds.
      static_assert(std::is_same_v<std::chrono::steady_clock::duration, std::chrono::nanoseconds>);
      const std::string report = fmt::format("{} {}", started.time_since_epoch().count(),
                                             std::chrono::steady_clock::now().time_since_epoch().count());
      [[maybe_unused]] const auto n = write(report_fd, report.data(), report.size());
    }
    return Outcome::ok;
  } catch (const std::exception& e) {
    const Outcome o = outcome_of(e);
    if (o != Outcome::out_of_memory)
      write_error(e.what());
    else
      write_error(dynamic_cast<const std::bad_alloc*>(&e) ? oom : fmt::format("{}: {}", oom, e.what()));
    return o;
  }
}

json trial_job(const SuiteConfig& c, const std::string& dir) {
  TrialSpec spec = c.spec;
  spec.out_dir = dir;
  spec.context = false;
  spec.skip_teardown = true;
  for (const auto& p : loaded_plugins()) spec.plugins.push_back(p.path);
  return to_json(spec);
}

namespace {

int g_threads_at_fork = -1;  // in the process that started the launcher, when it did

}  // namespace

std::unique_ptr<Launcher> start_trial_launcher() {
  // Forking is only safe from a single-threaded parent. OpenVDB's logger, log4cplus, starts a pool of
  // worker threads when the library loads, before main: stop it (logging still works without it).
  log4cplus::deinitialize();
  // TBB's one-time initialisation (hardware topology; no worker threads: those start with the first
  // parallel algorithm) is done here once, so each forked trial inherits it instead of paying for it again.
  (void)tbb::info::default_concurrency();
  { tbb::global_control warm(tbb::global_control::max_allowed_parallelism, tbb::info::default_concurrency()); }
  // The pool's threads are joined, but the kernel counts a joined thread until it has finished
  // exiting, a moment later (longer on a loaded machine): wait for that, up to a second.
  g_threads_at_fork = process_thread_count();
  for (int waited_ms = 0; g_threads_at_fork > 1 && waited_ms < 1000; ++waited_ms) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    g_threads_at_fork = process_thread_count();
  }
  if (g_threads_at_fork != 1)
    fmt::print(stderr, "growbench: warning: {} threads in the suite process before forking trials (expected 1)\n",
               g_threads_at_fork);
  return std::make_unique<Launcher>([](const std::string& description) {
    const json j = json::parse(description);
    const TrialSpec spec = trial_spec_from_json(j);
    return Launcher::Job{
        [spec](int report_fd) { return trial_exit_code(run_trial_child(spec, spec.out_dir, report_fd)); },
        (fs::path(spec.out_dir) / "log.txt").string()};
  });
}

namespace {

// One run of a suite into its output directory: results.json (rewritten), journal.jsonl (appended), and a
// folder per cell under trials/.
class SuiteRun {
 public:
  SuiteRun(const Suite& suite_in, const SuiteRunOptions& o) : suite_(suite_in), o_(o) {
    // Instruction counts: one repetition (they repeat exactly), no warm-up, one thread.
    if (o.instructions) {
      suite_.repetitions = 1;
      suite_.warmup = 0;
      for (auto& c : suite_.configs) c.spec.threads = 1;
      valgrind_ = find_program("valgrind");
      if (valgrind_.empty())
        throw InputError("--instructions needs valgrind (Debian's valgrind package; scripts/install-deps)");
      self_exe_ = fs::read_symlink("/proc/self/exe").string();
    }
    out_ = o.out_dir.empty() ? fs::path("out/suites") / suite_.name : fs::path(o.out_dir);
    results_path_ = out_ / "results.json";
    journal_path_ = out_ / "journal.jsonl";
    launcher_ = o.launcher;
    if (!o.instructions && !launcher_) {
      own_launcher_ = start_trial_launcher();
      launcher_ = own_launcher_.get();
    }
    // After the launcher starts, so that its processes do not hold the lock's descriptor.
    lock_ = FolderLock::take(out_.string(), o.resume ? "suite --resume" : "suite");
    make_directories((out_ / "trials").string());
  }

  std::string run() {
    open_results();
    add_cells();
    check_inputs();
    write_scene_files();
    if (o_.resume && fs::exists(journal_path_)) {
      if (const std::string torn = repair_journal(journal_path_.string()); !torn.empty())
        fmt::print(stderr,
                   "growbench: warning: {} ended in a line cut short ({} bytes, set aside in {}.torn); its trial "
                   "runs again\n",
                   journal_path_.string(), torn.size(), journal_path_.filename().string());
      replay_journal();
    }
    write_atomic(results_path_, results_text(results_));
    journal_.reset(std::fopen(journal_path_.c_str(), "a"));
    if (!journal_) throw std::runtime_error(fmt::format("{}: cannot open the journal", journal_path_.string()));
    auto last_snapshot = std::chrono::steady_clock::now();
    const std::vector<Job> jobs = plan_jobs();
    const bool tty = isatty(STDERR_FILENO) != 0 && !o_.quiet;
    const auto t_start = std::chrono::steady_clock::now();
    // Callgrind trials side by side (each cell once, so each in its own folder): their counts do not
    // depend on what else runs. Timed trials run one at a time, so that none disturbs another's timing.
    std::optional<OrderedPool<TrialProcess>> pool;
    const auto width = static_cast<std::size_t>(std::max(1, o_.instructions ? o_.jobs : 1));
    if (width > 1 && jobs.size() > 1)
      pool.emplace(jobs.size(), std::min(width, jobs.size()), [&](std::size_t i) { return start_job(jobs[i]); });
    for (std::size_t jn = 0; jn < jobs.size(); ++jn) {
      if (!o_.quiet) print_progress(jobs, jn, t_start, tty);
      const bool measured = finish_job(jobs[jn], pool ? pool->take(jn) : start_job(jobs[jn]));
      if (!o_.quiet) print_outcome(jobs, jn, tty);
      if (!measured) continue;  // a warm-up
      // Readable snapshots of the whole run every few seconds (always written atomically).
      if (std::chrono::steady_clock::now() - last_snapshot > std::chrono::seconds(10)) {
        write_snapshot();
        last_snapshot = std::chrono::steady_clock::now();
      }
    }
    results_.context.load_average_end = load_average();
    write_snapshot();
    if (tty) fmt::print(stderr, "\r{:<100}\r", "");
    return results_path_.string();
  }

 private:
  // Each distinct scene's meshes, light and camera once, as OUT/scenes/NAME-HASH.glb, for the report's 3D
  // views; results.json's "scenes" maps each content hash (the trials' scene_hash) to its file.
  void write_scene_files() {
    std::map<std::string, std::string> files;
    std::set<std::pair<std::string, std::vector<std::string>>> seen;
    for (const auto& c : suite_.configs) {
      if (!seen.insert({c.spec.scene, c.spec.scene_params}).second) continue;
      const Scene scene = load_scene(c.spec.scene, c.spec.scene_params);
      const std::string hash = scene.content_hash();
      if (files.count(hash)) continue;
      const std::string name = fmt::format("scenes/{}-{}.glb", safe_name(scene.name), hash);
      make_directories((out_ / "scenes").string());
      write_scene_glb((out_ / name).string(), scene);
      files[hash] = name;
    }
    results_.scenes = std::move(files);
  }

  struct Job {
    const SuiteConfig* cell;
    int repetition;  // -1: warm-up
  };
  // One trial's process and what it left: the record, read while the kernel is still tearing the child
  // down, and the child's report (steady-clock ns when it started, and when record.json was in place).
  struct TrialProcess {
    ChildResult cr;
    std::chrono::steady_clock::time_point t0, t_reaped;
    std::int64_t started_ns = 0, finished_ns = 0;
    std::optional<TrialRecord> rec;
    std::string rec_error;
    double read_record_s = 0.0;
    std::optional<std::uint64_t> oom_kills_before;  // the cgroup's count when the trial started
  };

  // The results of an earlier run (--resume) or fresh ones; the context is taken now, before any trial.
  void open_results() {
    if (!o_.resume && fs::exists(journal_path_) && !fs::exists(results_path_))
      throw InputError(
          fmt::format("{} holds a journal of an interrupted run: pass --resume to continue it, or another --out",
                      journal_path_.string()));
    if (fs::exists(results_path_)) {
      if (!o_.resume)
        throw InputError(fmt::format("{} already holds results: pass --resume to continue that run, or another --out",
                                     results_path_.string()));
      try {
        results_ = read_results(results_path_.string());
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: cannot resume, the file is not valid results JSON ({})",
                                     results_path_.string(), e.what()));
      }
      if (results_.suite_hash != suite_.hash)
        throw InputError(fmt::format("{}: cannot resume, it was written for a different version of {}",
                                     results_path_.string(), suite_.file));
      if (results_.repetitions != suite_.repetitions)
        throw InputError(fmt::format("{}: cannot resume, it ran {} repetitions per cell and this run asks {}",
                                     results_path_.string(), results_.repetitions, suite_.repetitions));
      check_same_plugins();
    } else {
      results_.mode = o_.instructions ? "instructions" : "timing";
      results_.suite = {suite_.name, suite_.file, suite_.description};
      results_.suite_hash = suite_.hash;
      results_.repetitions = suite_.repetitions;
      results_.shard = {o_.shard_index, o_.shard_count};
    }
    results_.context = run_context_record();
    results_.context.suite_file_hash = suite_.hash;
    if (g_threads_at_fork >= 0) results_.context.parent_threads_at_fork = g_threads_at_fork;
  }

  // A plugin rebuilt between a run and its --resume would mix two programs' trials under one name.
  void check_same_plugins() const {
    const auto now = loaded_plugins();
    for (const PluginOrigin& before : results_.context.plugins) {
      const auto same =
          std::find_if(now.begin(), now.end(), [&](const PluginOrigin& p) { return p.name == before.name; });
      if (same == now.end())
        throw InputError(fmt::format("{}: cannot resume, its trials ran plugin '{}' ({}), which this run does not load",
                                     results_path_.string(), before.name, before.path));
      if (same->hash != before.hash)
        throw InputError(
            fmt::format("{}: cannot resume, plugin '{}' has changed since its trials ran (xxh3 {} then, {} now, {}); "
                        "rerun in another --out",
                        results_path_.string(), before.name, before.hash, same->hash, same->path));
    }
  }

  // Indexes the cells already recorded, and creates entries for every cell of this shard.
  void add_cells() {
    for (std::size_t i = 0; i < results_.trials.size(); ++i) index_[results_.trials[i].id] = i;
    for (std::size_t i = 0; i < suite_.configs.size(); ++i) {
      if (static_cast<int>(i % static_cast<std::size_t>(o_.shard_count)) != o_.shard_index) continue;
      const SuiteConfig& c = suite_.configs[i];
      cells_.push_back(&c);
      if (index_.count(c.id)) continue;
      index_[c.id] = results_.trials.size();
      SuiteCell t;
      t.id = c.id;
      t.label = c.label;
      t.algorithm = c.spec.algorithm;
      t.scene = c.scene_name;
      t.scene_spec = c.spec.scene;
      t.seed = c.spec.seed;
      t.sweep = c.sweep;
      t.spec = c.spec;
      results_.trials.push_back(std::move(t));
    }
  }

  // The files an algorithm's text parameters name (a grammar, a mask, a points file, an organ OBJ) only the
  // algorithm reads, as it starts. So each cell that sets a text parameter to a combination not seen
  // before starts once, as a trial of no steps in its own process (with the suite's limits), before any
  // trial runs; an input it refuses stops the suite here instead of failing every trial of the cell.
  void check_inputs() {
    std::set<std::string> seen;
    const fs::path root = out_ / "checks";
    for (const SuiteConfig& c : suite_.configs) {
      const std::string texts = text_assignments(c.spec);
      if (texts.empty() || !seen.insert(c.spec.algorithm + '\n' + texts).second) continue;
      SuiteConfig check = c;
      check.spec.max_steps = 0;
      check.spec.metrics = false;
      check.spec.frame_every = 0;
      const fs::path dir = root / std::to_string(seen.size());
      make_directories(dir.string());
      const std::string job = json_text(trial_job(check, dir.string()), -1);
      const ChildLimits limits{suite_.timeout_s, suite_.memory_limit_bytes};
      ChildResult r;
      if (launcher_) {
        r = launcher_->run(job, limits, {});
      } else {  // --instructions: no launcher; `growbench trial`, as the trials run, but without callgrind
        write_atomic(dir / "spec.json", job);
        r = run_program({self_exe_, "trial", (dir / "spec.json").string()}, "", limits, (dir / "log.txt").string());
      }
      // Only refused input stops the suite: a crash or a hang is the trials' to record.
      if (!r.timed_out && r.signal == 0 && outcome_of_trial_exit(r.exit_code) == Outcome::invalid_input) {
        const std::string error = read_text((dir / "error.txt").string());
        std::error_code ec;
        fs::remove_all(root, ec);
        throw InputError(fmt::format("{}: cell {} cannot start: {}", suite_.file, c.id, error));
      }
    }
    std::error_code ec;
    fs::remove_all(root, ec);
  }

  // The cell's assignments to text parameters, one per line ("" when none).
  static std::string text_assignments(const TrialSpec& spec) {
    const auto& table = find_algorithm(spec.algorithm).info().params;
    std::string out;
    for (const std::string& a : spec.params) {
      const auto eq = a.find('=');
      const auto it =
          std::find_if(table.begin(), table.end(), [&](const ParamSpec& p) { return p.name == a.substr(0, eq); });
      if (it != table.end() && it->type == ParamType::String && eq + 1 < a.size()) out += a + '\n';
    }
    return out;
  }

  // Repetitions finished after the last snapshot (or before a kill) come back from the journal.
  void replay_journal() {
    for (const JournalEntry& e : read_journal(journal_path_.string())) {
      const auto it = index_.find(e.id);
      if (it == index_.end()) continue;
      SuiteCell& t = results_.trials[it->second];
      bool have = false;
      for (const auto& smp : t.samples) have = have || smp.repetition == e.sample.repetition;
      if (!have) apply_sample(t, e.sample, e.cell);
    }
  }

  // Warm-ups, then repetitions, each pass over the interleaved cells; repetitions already done are skipped.
  [[nodiscard]] std::vector<Job> plan_jobs() const {
    std::vector<Job> jobs;
    if (!cells_.empty())
      for (int w = 0; w < suite_.warmup; ++w) jobs.push_back({cells_.front(), -1});
    for (int r = 0; r < suite_.repetitions; ++r)
      for (const auto* c : cells_) {
        bool done = false;
        for (const auto& s : results_.trials[index_.at(c->id)].samples) done = done || s.repetition == r;
        if (!done) jobs.push_back({c, r});
      }
    if (o_.resume && jobs.size() == static_cast<std::size_t>(cells_.empty() ? 0 : suite_.warmup)) jobs.clear();
    return jobs;
  }

  void print_progress(const std::vector<Job>& jobs, std::size_t jn, std::chrono::steady_clock::time_point t_start,
                      bool tty) const {
    const Job& job = jobs[jn];
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    const double eta = jn > 0 ? el / static_cast<double>(jn) * static_cast<double>(jobs.size() - jn) : 0.0;
    const std::string what =
        job.repetition < 0 ? "warm-up" : fmt::format("rep {}/{}", job.repetition + 1, suite_.repetitions);
    const std::string line = fmt::format("[{}/{}] {} ({}){}", jn + 1, jobs.size(), job.cell->id, what,
                                         jn > 0 ? fmt::format(", ETA {:.0f} s", eta) : std::string());
    if (tty)
      fmt::print(stderr, "\r{:<100}", line.substr(0, 100));
    else
      fmt::print(stderr, "{}", line);
  }
  // Ends the progress line with how the trial ended: "ok, 1.2 s", or its status and the start of its message.
  void print_outcome(const std::vector<Job>& jobs, std::size_t jn, bool tty) const {
    std::string outcome = fmt::format("{}, {:.1f} s", last_outcome_.status, last_outcome_.wall_s);
    if (last_outcome_.message) outcome += ": " + utf8_excerpt(*last_outcome_.message, 60);
    if (!tty) {
      fmt::print(stderr, " -> {}\n", outcome);
      return;
    }
    const Job& job = jobs[jn];  // the line again, now with its outcome, kept to 100 columns
    const std::string line = fmt::format("[{}/{}] {} -> {}", jn + 1, jobs.size(), job.cell->id, outcome);
    fmt::print(stderr, "\r{:<100}{}", line.substr(0, 100), last_outcome_.status == "ok" ? "" : "\n");
  }

  // Runs the cell's trial in its own process: forked by the launcher, or under callgrind as `growbench trial`.
  TrialProcess run_process(const SuiteConfig& c, const fs::path& dir) {
    TrialProcess p;
    const fs::path rec_path = dir / "record.json";
    auto read_record = [&] {
      const auto r0 = std::chrono::steady_clock::now();
      try {
        p.rec = read_trial_record(rec_path.string());
      } catch (const std::exception& e) {
        p.rec.reset();
        p.rec_error = e.what();
      }
      p.read_record_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
    };
    p.oom_kills_before = oom_kills();
    p.t0 = std::chrono::steady_clock::now();
    if (o_.instructions) {
      // Under callgrind: the trial runs in a fresh growbench process (`growbench trial`), single-threaded,
      // and dumps its instruction count at the end of every phase (harness/run/trial.cpp).
      write_atomic(dir / "spec.json", json_text(trial_job(c, dir.string()), -1));
      for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().rfind("callgrind.out", 0) == 0) fs::remove(e.path());
      std::vector<std::string> args = {valgrind_, "--tool=callgrind",
                                       "--callgrind-out-file=" + (dir / "callgrind.out").string(),
                                       // Ir do not depend on the cache model; it is pinned anyway, so a
                                       // run with --cache-sim=yes would be comparable across hosts.
                                       "--cache-sim=no", "--I1=32768,8,64", "--D1=32768,8,64", "--LL=8388608,16,64",
                                       "--instr-atstart=no",  // the trial turns it on per phase
                                       self_exe_, "trial", (dir / "spec.json").string()};
      p.cr = run_program(args, "", {suite_.timeout_s * kCallgrindSlowdown, 0}, (dir / "log.txt").string());
    } else {
      const ChildLimits limits{suite_.timeout_s, suite_.memory_limit_bytes};
      p.cr = launcher_->run(json_text(trial_job(c, dir.string()), -1), limits, [&](const std::string& report) {
        std::istringstream in(report);
        in >> p.started_ns >> p.finished_ns;
        read_record();
      });
    }
    p.t_reaped = std::chrono::steady_clock::now();
    if (!p.cr.timed_out && p.cr.signal == 0 && p.cr.exit_code == trial_exit_code(Outcome::ok) && fs::exists(rec_path) &&
        !p.rec && p.rec_error.empty())
      read_record();  // no report (callgrind trials)
    return p;
  }

  // The sample's status and message from how the trial's process ended.
  void judge(const TrialProcess& p, const fs::path& dir, SuiteSample& sample) const {
    const ChildResult& cr = p.cr;
    const fs::path rec_path = dir / "record.json", err_path = dir / "error.txt";
    std::string message;
    Outcome outcome = Outcome::ok;
    if (cr.timed_out) {
      outcome = Outcome::timeout;
      message = fmt::format("killed after {} s", suite_.timeout_s);
    } else if (cr.signal != 0) {
      // A SIGKILL this process did not send: the kernel's OOM killer when its cgroup counted a kill during the
      // trial (or when the kernel does not say), another process's otherwise.
      const bool oom = cr.signal == SIGKILL && (!p.oom_kills_before || oom_kills() > p.oom_kills_before);
      outcome = oom ? Outcome::out_of_memory : Outcome::crashed;
      message = signal_name(cr.signal);
      if (cr.signal == SIGKILL)
        message += oom ? (p.oom_kills_before ? ", by the kernel's OOM killer" : ", probably by the kernel's OOM killer")
                       : ", not by the kernel's OOM killer";
    } else if (outcome_of_trial_exit(cr.exit_code) == Outcome::ok && fs::exists(rec_path)) {
      if (!p.rec) {
        outcome = Outcome::crashed;
        message = fmt::format("{} is unreadable: {}", rec_path.string(), p.rec_error);
      }
    } else if (fs::exists(err_path) && cr.exit_code != trial_exit_code(Outcome::ok)) {
      // The trial's own report: error.txt is written only where it catches its failure, with its code.
      message = read_message(err_path);
      outcome = outcome_of_trial_exit(cr.exit_code);
    } else {
      // An exit the trial did not report (a plugin's exit(), or an exit before the record was written):
      // its status is not a verdict on the input.
      outcome = Outcome::failed;
      message = fmt::format(
          "the trial process exited with status {} without reporting why (an exit() in the "
          "algorithm, or before its record was written)",
          cr.exit_code);
    }
    sample.status = std::string(status_name(outcome));
    if (!message.empty()) sample.message = message;
  }

  // Where the time outside the phases goes (README, "Harness overhead"): fork to the child's start; the
  // child's own bookkeeping (measuring, record.json, snapshot); the kernel tearing the child down (freeing
  // its memory), during which this process reads the record; and this process's work. Everything runs to
  // just before the journal append (one short write).
  static void account_overhead(const TrialProcess& p, double inside, SuiteSample& sample) {
    const auto now = std::chrono::steady_clock::now();
    sample.outside_phases_s = std::chrono::duration<double>(now - p.t0).count() - inside;
    if (p.started_ns <= 0) return;
    const auto secs = [](std::chrono::steady_clock::time_point tp) {
      return std::chrono::duration<double>(tp.time_since_epoch()).count();
    };
    const double started = 1e-9 * static_cast<double>(p.started_ns),
                 finished = 1e-9 * static_cast<double>(p.finished_ns);
    const double launch = started - secs(p.t0), bookkeeping = finished - started - inside;
    const double parent = p.read_record_s + std::chrono::duration<double>(now - p.t_reaped).count();
    sample.launch_s = launch;
    sample.launch_fork_s = started - 1e-9 * static_cast<double>(p.cr.spawn_ns);
    sample.child_bookkeeping_s = bookkeeping;
    sample.teardown_s = secs(p.t_reaped) - finished;
    sample.parent_s = parent;
    sample.harness_overhead_s = launch + bookkeeping + parent;
  }

  // Runs one job's trial in a clean folder.
  TrialProcess start_job(const Job& job) {
    const fs::path dir = out_ / "trials" / job.cell->id;
    make_directories(dir.string());
    fs::remove(dir / "record.json");
    fs::remove(dir / "error.txt");
    return run_process(*job.cell, dir);
  }

  // Keeps what a job's trial left; false for a warm-up, which is run but not kept.
  bool finish_job(const Job& job, const TrialProcess& p) {
    const SuiteConfig& c = *job.cell;
    const fs::path dir = out_ / "trials" / c.id;
    SuiteSample sample;
    sample.repetition = job.repetition;
    sample.child_wall_s = p.cr.wall_s;
    sample.child_user_s = p.cr.user_s;
    sample.child_system_s = p.cr.system_s;
    sample.child_max_rss_bytes = p.cr.max_rss_bytes;
    judge(p, dir, sample);
    last_outcome_ = {sample.status, p.cr.wall_s, sample.message};
    stop_if_the_disk_is_full(c, sample);
    std::optional<InstructionCounts> instructions;
    if (sample.status == "ok" && o_.instructions) sample.instructions = instructions = read_callgrind_phases(dir);
    if (job.repetition < 0) return false;
    SuiteCell& t = results_.trials[index_[c.id]];
    std::optional<CellResults> cell;
    if (sample.status == "ok") {
      const TrialRecord& rec = *p.rec;
      sample.phases = rec.phases;
      double inside = 0.0;
      rec.phases.each([&](Phase, const PhaseMeasures& m) { inside += m.wall_s; });
      sample.steps = rec.results.steps;
      sample.geometry_hash = rec.results.geometry_hash;
      if (!t.results.plant) cell = cell_results_of(rec, instructions);
      account_overhead(p, inside, sample);
    }
    // The journal line is the durable record: appended and flushed before the next trial starts, so an
    // interrupted suite (even by kill -9) loses at most the trial in flight.
    const std::string line = json_text(to_json(JournalEntry{c.id, sample, cell}), -1);
    if (std::fputs(line.c_str(), journal_.get()) < 0 || std::fflush(journal_.get()) != 0)
      throw InputError(fmt::format("{}: cannot append to the journal: {}; the trial runs again with --resume",
                                   journal_path_.string(), std::strerror(errno)));
    apply_sample(t, sample, cell);
    return true;
  }

  // A trial that failed for want of disk space says nothing of its input: the suite stops (exit 2) before
  // journaling it, so that --resume on a disk with room runs it again.
  void stop_if_the_disk_is_full(const SuiteConfig& c, const SuiteSample& sample) const {
    if (sample.status == "ok") return;
    const std::string full = std::strerror(ENOSPC);
    // The trial's own error.txt may not have fitted either: then the folder's free space tells. A file
    // system that reports no blocks at all (some virtual and network ones) tells nothing; root may use the
    // blocks reserved for it.
    struct statvfs fs_stat {};
    const bool known = statvfs(out_.c_str(), &fs_stat) == 0 && fs_stat.f_blocks > 0;
    const auto free_blocks = geteuid() == 0 ? fs_stat.f_bfree : fs_stat.f_bavail;
    const bool no_room = known && static_cast<double>(free_blocks) * static_cast<double>(fs_stat.f_frsize) < 1 << 20;
    if (!no_room && (!sample.message || sample.message->find(full) == std::string::npos)) return;
    throw InputError(fmt::format("{}: {} (cell {}); free space and continue with --resume: that trial runs again",
                                 out_.string(), full, c.id));
  }

  void write_snapshot() {
    write_atomic(results_path_, results_text(results_));
    write_atomic(out_ / "results.csv", results_csv(results_));
  }

  Suite suite_;
  const SuiteRunOptions& o_;
  std::string valgrind_, self_exe_;
  fs::path out_, results_path_, journal_path_;
  std::unique_ptr<Launcher> own_launcher_;
  FolderLock lock_;  // released before the launcher ends (members end in reverse order)
  struct {
    std::string status;
    double wall_s = 0.0;
    std::optional<std::string> message;
  } last_outcome_;  // of the trial finished last, for the progress line
  Launcher* launcher_ = nullptr;
  ResultsFile results_;
  std::map<std::string, std::size_t> index_;  // cell id -> index in results_.trials
  std::vector<const SuiteConfig*> cells_;     // this shard's, in run order
  std::unique_ptr<FILE, int (*)(FILE*)> journal_{nullptr, &std::fclose};
};

}  // namespace

std::string run_suite(const Suite& suite, const SuiteRunOptions& options) {
  return SuiteRun(suite, options).run();
}

}  // namespace growbench
