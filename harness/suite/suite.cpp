#include "harness/record/files.hpp"
#include "harness/suite/suite.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <new>
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
#include "harness/output/exporters.hpp"
#include "harness/record/record.hpp"
#include "harness/run/process.hpp"
#include "harness/stats/stats.hpp"
#include "scenes/scene_library.hpp"

namespace growbench {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string read_text(const std::string& path) {
  return read_input_file(path);
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
    only_keys(j, "",
              {"schema_version", "name", "description", "repetitions", "warmup", "threads", "timeout_s",
               "memory_limit_mb", "max_steps", "seeds", "budget", "glb", "scenes", "algorithms", "plugins"});
    if (!j.contains("schema_version") || j["schema_version"] != 1) fail("/schema_version", "expected 1");
    Suite s;
    s.file = file();
    s.hash = fmt::format("{:016x}", XXH3_64bits(text.data(), text.size()));
    const Common common = read_settings(j, s);
    const std::vector<SceneEntry> scenes = read_scenes(j);
    load_listed_plugins(j);
    const std::vector<AlgoEntry> algos = read_algorithms(j);
    make_cells(common, scenes, algos, s);
    return s;
  }

 private:
  // What every cell shares, from the top level of the file.
  struct Common {
    int threads = 0, max_steps = 5000;
    std::vector<std::uint64_t> seeds = {1};
    std::size_t budget_nodes = 0;
    double budget_length = 0.0;
    GlbLayout glb = kDefaultGlbLayout;
  };
  struct SceneEntry {
    std::string spec, name;
    std::vector<std::string> params;
  };
  struct AlgoEntry {
    std::string label, name, fault, leaf_obj;
    std::vector<std::string> organs;  // the organ pass's key=value
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
    s.name = string_field(j, "", "name", fs::path(file()).stem().string(), "the suite's name");
    s.description = string_field(j, "", "description", "", "a description");
    if (j.contains("repetitions")) s.repetitions = static_cast<int>(number(j["repetitions"], "/repetitions", 1, 1000));
    if (j.contains("warmup")) s.warmup = static_cast<int>(number(j["warmup"], "/warmup", 0, 100));
    if (j.contains("timeout_s")) s.timeout_s = number(j["timeout_s"], "/timeout_s", 0.001, 1e6);
    if (j.contains("memory_limit_mb"))
      s.memory_limit_bytes = static_cast<std::uint64_t>(number(j["memory_limit_mb"], "/memory_limit_mb", 64, 1e7))
                             << 20;
    Common c;
    if (j.contains("threads")) c.threads = static_cast<int>(number(j["threads"], "/threads", 0, kMaxThreads));
    if (j.contains("max_steps")) c.max_steps = static_cast<int>(number(j["max_steps"], "/max_steps", 0, 1e9));
    if (j.contains("seeds")) {
      if (!j["seeds"].is_array() || j["seeds"].empty()) fail("/seeds", "expected a non-empty array of seeds");
      c.seeds.clear();
      for (std::size_t i = 0; i < j["seeds"].size(); ++i)
        c.seeds.push_back(static_cast<std::uint64_t>(number(j["seeds"][i], fmt::format("/seeds/{}", i), 0, 9e15)));
    }
    if (j.contains("budget")) {
      only_keys(j["budget"], "/budget", {"nodes", "length_m"});
      if (j["budget"].contains("nodes"))
        c.budget_nodes = static_cast<std::size_t>(number(j["budget"]["nodes"], "/budget/nodes", 0, 1e12));
      if (j["budget"].contains("length_m"))
        c.budget_length = number(j["budget"]["length_m"], "/budget/length_m", 0, 1e12);
    }
    if (j.contains("glb")) {
      const std::string name = string_field(j, "", "glb", "", "the layout of plant.glb: plain, instanced or compact");
      try {
        c.glb = parse_glb_layout(name);
      } catch (const InputError& err) {
        fail("/glb", err.what());
      }
    }
    return c;
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
        se.name = string_field(e, path, "name", "", "the scene's display name");
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

  std::vector<AlgoEntry> read_algorithms(const json& j) const {
    std::vector<AlgoEntry> algos;
    if (!j.contains("algorithms") || !j["algorithms"].is_array() || j["algorithms"].empty())
      fail("/algorithms", "expected a non-empty array of algorithm entries");
    std::set<std::string> labels;
    for (std::size_t i = 0; i < j["algorithms"].size(); ++i) {
      algos.push_back(read_algorithm(j["algorithms"][i], fmt::format("/algorithms/{}", i), labels));
    }
    return algos;
  }

  // One entry of "algorithms"; its label must not be in `labels` (the entries before it), and is added.
  AlgoEntry read_algorithm(const json& e, const std::string& path, std::set<std::string>& labels) const {
    AlgoEntry a;
    if (e.is_string()) {
      a.name = e.get<std::string>();
    } else {
      only_keys(e, path, {"name", "label", "params", "sweep", "fault", "leaf_obj", "organs"});
      if (!e.contains("name") || !e["name"].is_string()) fail(path + "/name", "expected the algorithm's name");
      a.name = e["name"].get<std::string>();
      a.label = string_field(e, path, "label", "", "the entry's label");
      a.fault = string_field(e, path, "fault", "", "a fault to inject (crash, hang, oom, throw or slow:N)");
      if (e.contains("leaf_obj")) {
        if (!e["leaf_obj"].is_string()) fail(path + "/leaf_obj", "expected the path of an OBJ file");
        a.leaf_obj = relative_to_suite(e["leaf_obj"].get<std::string>());
        try {
          (void)load_organ_obj(a.leaf_obj);
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
      a.organs.push_back(k + "=" + value_text(v));
    }
    try {
      (void)read_organ_options(a.organs);
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
            c.spec.algorithm = a.name;
            c.spec.scene = sc.spec;
            c.spec.scene_params = sc.params;
            c.spec.params = a.params;
            c.spec.seed = seed;
            c.spec.threads = common.threads;
            c.spec.max_steps = common.max_steps;
            c.spec.budget_nodes = common.budget_nodes;
            c.spec.budget_length_m = common.budget_length;
            c.spec.glb = common.glb;
            c.spec.fault = a.fault;
            c.spec.mesher.leaf_obj = a.leaf_obj;
            c.spec.organs = a.organs;
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

// Exit codes of a trial child.
constexpr int kExitOk = 0, kExitInvalid = 2, kExitOom = 3, kExitError = 4;

std::string csv_row(const std::vector<std::string>& cells) {
  std::string row;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    std::string c = cells[i];
    if (c.find_first_of(",\"\n") != std::string::npos) {
      std::string q = "\"";
      for (const char ch : c) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
      c = q + "\"";
    }
    row += (i ? "," : "") + c;
  }
  return row;
}

// The CSV's phase columns, in the order trials run them.
const std::vector<std::string> kPhases = {"scene_load", "query_build", "growth", "organs",
                                          "meshing",    "export",      "metrics"};

// A number as the JSON has it ("" when absent), so the CSV and results.json agree digit for digit.
template <class T>
std::string num(const std::optional<T>& v) {
  return v ? json(*v).dump() : std::string();
}
template <class T>
std::string num(const T& v) {
  return json(v).dump();
}

std::string results_csv(const ResultsFile& results) {
  std::vector<std::string> head = {"id", "label", "algorithm", "scene", "seed", "sweep", "repetition", "status"};
  for (const auto& ph : kPhases) {
    head.push_back(ph + "_wall_s");
    head.push_back(ph + "_cpu_s");
    head.push_back(ph + "_peak_rss_bytes");
    head.push_back(ph + "_alloc_count");
  }
  for (const auto& k :
       {"child_wall_s", "child_max_rss_bytes", "harness_overhead_s", "nodes", "leaves", "total_length_m", "obj_bytes",
        "ply_bytes", "glb_bytes", "coverage", "attached_fraction", "penetration_nodes", "geometry_hash"})
    head.emplace_back(k);
  std::string out = csv_row(head) + "\n";
  for (const auto& t : results.trials) {
    const CellResults& c = t.results;
    for (const auto& s : t.samples) {
      std::vector<std::string> row = {t.id,        t.label,        t.algorithm,       t.scene,
                                      num(t.seed), t.sweep.dump(), num(s.repetition), s.status};
      for (const auto& ph : kPhases) {
        const PhaseMeasures* p = s.phases ? s.phases->find(ph) : nullptr;
        row.push_back(p ? num(p->wall_s) : "");
        row.push_back(p ? num(p->cpu_s) : "");
        row.push_back(p ? num(p->peak_rss_bytes) : "");
        row.push_back(p ? num(p->alloc_count) : "");
      }
      const bool ok = s.status == "ok";
      const OutputBytes b = ok && c.output_bytes ? *c.output_bytes : OutputBytes{};
      auto metric = [&](const char* k) {
        return ok && c.metrics && c.metrics->contains(k) ? (*c.metrics)[k].dump() : std::string();
      };
      row.push_back(num(s.child_wall_s));
      row.push_back(num(s.child_max_rss_bytes));
      row.push_back(num(s.harness_overhead_s));
      row.push_back(ok && c.counts ? num(c.counts->nodes) : "");
      row.push_back(ok && c.counts ? num(c.counts->leaves) : "");
      row.push_back(ok ? num(c.total_length_m) : "");
      row.push_back(num(b.obj));
      row.push_back(num(b.ply));
      row.push_back(num(b.glb));
      row.push_back(metric("coverage"));
      row.push_back(metric("attached_fraction"));
      row.push_back(metric("penetration_nodes"));
      row.push_back(ok && c.geometry_hash ? *c.geometry_hash : "");
      out += csv_row(row) + "\n";
    }
  }
  return out;
}

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
    if (!phase.empty() && have) out[phase] = ir;
    fs::remove(f);
  }
  return out;
}

// The per-cell fields of a successful repetition's record: all of them for the cell's first success, else
// just the geometry hash and counts, which are compared to catch nondeterminism.
CellResults cell_results_of(const TrialRecord& rec, bool first, const std::optional<InstructionCounts>& instructions) {
  CellResults c;
  c.geometry_hash = rec.geometry_hash;
  c.counts = rec.counts;
  if (!first) return c;
  c.output_bytes = rec.output_bytes;
  c.metrics = rec.metrics;
  c.total_length_m = rec.total_length_m;
  c.steps = rec.steps;
  c.stopped_by = rec.stopped_by;
  c.curve = rec.curve;
  c.params = rec.params;
  c.algorithm_stats = rec.algorithm_stats;
  c.threads = rec.threads;
  c.scene_hash = rec.scene.hash;
  AllocByPhase alloc;
  rec.phases.each([&](std::string_view k, const PhaseMeasures& p) {
    alloc[std::string(k)] = {p.alloc_count, p.alloc_bytes};
  });
  c.alloc = alloc;
  c.instructions = instructions;
  c.organs = rec.organs;
  return c;
}

// Every field `from` has, into `to`.
void take_fields(CellResults& to, const CellResults& from) {
  auto take = [](auto& a, const auto& b) {
    if (b) a = b;
  };
  take(to.geometry_hash, from.geometry_hash);
  take(to.counts, from.counts);
  take(to.output_bytes, from.output_bytes);
  take(to.metrics, from.metrics);
  take(to.total_length_m, from.total_length_m);
  take(to.steps, from.steps);
  take(to.stopped_by, from.stopped_by);
  take(to.curve, from.curve);
  take(to.params, from.params);
  take(to.algorithm_stats, from.algorithm_stats);
  take(to.threads, from.threads);
  take(to.scene_hash, from.scene_hash);
  take(to.alloc, from.alloc);
  take(to.instructions, from.instructions);
}

// The growth phase's wall time of every ok repetition of a cell, in repetition order.
std::vector<double> growth_times(const SuiteCell& t) {
  std::vector<double> v;
  for (const auto& s : t.samples)
    if (s.status == "ok" && s.phases && s.phases->growth) v.push_back(s.phases->growth->wall_s);
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
  if (sample.status == "ok" && cell) {
    if (!t.results.geometry_hash) {
      take_fields(t.results, *cell);
    } else if (t.results.geometry_hash != cell->geometry_hash || t.results.counts != cell->counts) {
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
// ok repetitions pooled, as the report's table shows them.
ResultsSummary results_summary(const std::vector<SuiteCell>& trials) {
  ResultsSummary out;
  std::vector<std::vector<double>> times;
  for (const auto& t : trials) {
    const std::vector<double> growth = growth_times(t);
    if (t.status != "ok" || growth.empty()) continue;
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
  if (!fs::exists(path)) throw InputError(fmt::format("{}: no such suite file", path));
  return SuiteReader(path).read();
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
  for (std::size_t k = 0; k < total; ++k) {
    const std::vector<SuiteCell>& trials = shards[slot[k % static_cast<std::size_t>(count)]].trials;
    const std::size_t at = k / static_cast<std::size_t>(count);
    if (at >= trials.size())
      throw InputError(fmt::format("merge: shard {} has fewer cells than its suite gives it", k % count));
    merged.trials.push_back(trials[at]);
  }
  if (!differ.empty()) merged.context.mixed_machines = true;
  merged.renders.reset();    // per-shard render summaries do not describe the merged grid
  update_summaries(merged);  // the seeds of one entry and scene may have run in different shards
  return merged;
}

json merge_results(const std::vector<json>& shards, const std::vector<std::string>& names, bool mixed_machines) {
  std::vector<ResultsFile> typed;
  for (std::size_t k = 0; k < shards.size(); ++k) typed.push_back(from_json<ResultsFile>(shards[k], names.at(k)));
  return to_json(merge_results(typed, names, mixed_machines));
}

int run_trial_child(const TrialSpec& spec, const std::string& dir_name, int report_fd) {
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
  exit_on_escaped_bad_alloc(kExitOom, oom, (dir / "error.txt").string());  // a library's noexcept code, its threads
  try {
    run_trial(spec);
    if (report_fd >= 0) {
      // steady_clock is CLOCK_MONOTONIC, comparable with the parent's clock; integer nanoseconds.
      static_assert(std::is_same_v<std::chrono::steady_clock::duration, std::chrono::nanoseconds>);
      const std::string report = fmt::format("{} {}", started.time_since_epoch().count(),
                                             std::chrono::steady_clock::now().time_since_epoch().count());
      [[maybe_unused]] const auto n = write(report_fd, report.data(), report.size());
    }
    return kExitOk;
  } catch (const InputError& e) {
    write_error(e.what());
    return kExitInvalid;
  } catch (const std::exception& e) {
    if (is_out_of_memory(e)) {
      write_error(dynamic_cast<const std::bad_alloc*>(&e) ? oom : fmt::format("{}: {}", oom, e.what()));
      return kExitOom;
    }
    write_error(e.what());
    return kExitError;
  }
}

json trial_job(const SuiteConfig& c, const std::string& dir) {
  TrialSpecRecord spec = to_record(c.spec);
  spec.out_dir = dir;
  spec.context = false;
  spec.skip_teardown = true;
  std::vector<std::string> plugins;
  for (const auto& p : loaded_plugins()) plugins.push_back(p.path);
  if (!plugins.empty()) spec.plugins = std::move(plugins);
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
    return Launcher::Job{[spec](int report_fd) { return run_trial_child(spec, spec.out_dir, report_fd); },
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
    make_directories((out_ / "trials").string());
    launcher_ = o.launcher;
    if (!o.instructions && !launcher_) {
      own_launcher_ = start_trial_launcher();
      launcher_ = own_launcher_.get();
    }
  }

  std::string run() {
    open_results();
    add_cells();
    check_inputs();
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
    for (std::size_t jn = 0; jn < jobs.size(); ++jn) {
      if (!o_.quiet) print_progress(jobs, jn, t_start, tty);
      if (!run_job(jobs[jn])) continue;  // a warm-up
      // Readable snapshots of the whole run every few seconds (always written atomically).
      if (std::chrono::steady_clock::now() - last_snapshot > std::chrono::seconds(10)) {
        write_snapshot();
        last_snapshot = std::chrono::steady_clock::now();
      }
    }
    write_snapshot();
    if (tty) fmt::print(stderr, "\r{:<100}\r", "");
    return results_path_.string();
  }

 private:
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
      t.spec = to_record(c.spec);
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
      if (!r.timed_out && r.signal == 0 && r.exit_code == kExitInvalid) {
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
      fmt::print(stderr, "{}\n", line);
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
    if (!p.cr.timed_out && p.cr.signal == 0 && p.cr.exit_code == kExitOk && fs::exists(rec_path) && !p.rec &&
        p.rec_error.empty())
      read_record();  // no report (callgrind trials)
    return p;
  }

  // The sample's status and message from how the trial's process ended.
  void judge(const TrialProcess& p, const fs::path& dir, SuiteSample& sample) const {
    const ChildResult& cr = p.cr;
    const fs::path rec_path = dir / "record.json", err_path = dir / "error.txt";
    std::string message;
    if (cr.timed_out) {
      sample.status = "timeout";
      message = fmt::format("killed after {} s", suite_.timeout_s);
    } else if (cr.signal != 0) {
      // SIGKILL that we did not send is the kernel's OOM killer.
      sample.status = cr.signal == SIGKILL ? "out_of_memory" : "crashed";
      message = signal_name(cr.signal);
    } else if (cr.exit_code == kExitOk && fs::exists(rec_path)) {
      if (!p.rec) {
        sample.status = "crashed";
        message = fmt::format("{} is unreadable: {}", rec_path.string(), p.rec_error);
      } else {
        sample.status = "ok";
      }
    } else {
      message = fs::exists(err_path) ? read_text(err_path.string()) : fmt::format("exit code {}", cr.exit_code);
      sample.status = cr.exit_code == kExitInvalid ? "invalid_input"
                      : cr.exit_code == kExitOom   ? "out_of_memory"
                                                   : "crashed";
    }
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

  // Runs one job; false for a warm-up, which is run but not kept.
  bool run_job(const Job& job) {
    const SuiteConfig& c = *job.cell;
    const fs::path dir = out_ / "trials" / c.id;
    make_directories(dir.string());
    fs::remove(dir / "record.json");
    fs::remove(dir / "error.txt");
    const TrialProcess p = run_process(c, dir);
    SuiteSample sample;
    sample.repetition = job.repetition;
    sample.child_wall_s = p.cr.wall_s;
    sample.child_user_s = p.cr.user_s;
    sample.child_system_s = p.cr.system_s;
    sample.child_max_rss_bytes = p.cr.max_rss_bytes;
    judge(p, dir, sample);
    std::optional<InstructionCounts> instructions;
    if (sample.status == "ok" && o_.instructions) sample.instructions = instructions = read_callgrind_phases(dir);
    if (job.repetition < 0) return false;
    SuiteCell& t = results_.trials[index_[c.id]];
    std::optional<CellResults> cell;
    if (sample.status == "ok") {
      const TrialRecord& rec = *p.rec;
      sample.phases = rec.phases;
      double inside = 0.0;
      rec.phases.each([&](std::string_view, const PhaseMeasures& m) { inside += m.wall_s; });
      sample.steps = rec.steps;
      cell = cell_results_of(rec, !t.results.geometry_hash, instructions);
      account_overhead(p, inside, sample);
    }
    // The journal line is the durable record: appended and flushed before the next trial starts, so an
    // interrupted suite (even by kill -9) loses at most the trial in flight.
    const std::string line = json_text(to_json(JournalEntry{c.id, sample, cell}), -1);
    if (std::fputs(line.c_str(), journal_.get()) < 0 || std::fflush(journal_.get()) != 0)
      throw std::runtime_error(fmt::format("{}: cannot append to the journal", journal_path_.string()));
    apply_sample(t, sample, cell);
    return true;
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
