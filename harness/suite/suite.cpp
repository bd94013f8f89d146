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
#include "core/errors.hpp"
#include "core/json_util.hpp"
#include "harness/output/exporters.hpp"
#include "harness/run/process.hpp"
#include "scenes/scene_library.hpp"

namespace growbench {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string read_text(const std::string& path) { return read_text_file(path); }

void write_atomic(const fs::path& path, const std::string& text) { write_file_atomic(path.string(), text.data(), text.size()); }

std::string value_text(const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }


class SuiteReader : public JsonPathReader {
 public:
  explicit SuiteReader(const std::string& file) : JsonPathReader(file), dir_(fs::path(file).parent_path()) {}
  double number(const json& j, const std::string& path, double lo, double hi) const {
    if (!j.is_number() || j.get<double>() < lo || j.get<double>() > hi)
      fail(path, fmt::format("expected a number in [{}, {}], got {}", lo, hi, j.dump()));
    return j.get<double>();
  }
  // A path in a suite file, relative to the suite file.
  std::string relative_to_suite(const std::string& path) const {
    const fs::path p(path);
    return (p.is_absolute() ? p : dir_ / p).lexically_normal().string();
  }
  // Scene specs in suites: mesh:PATH and *.json are relative to the suite file (mesh:NAME is a bundled mesh).
  std::string scene_spec(const std::string& spec) const {
    if (spec.rfind("mesh:", 0) == 0 && !is_mesh_name(spec.substr(5))) return "mesh:" + relative_to_suite(spec.substr(5));
    if (spec.size() > 5 && spec.substr(spec.size() - 5) == ".json") return relative_to_suite(spec);
    return spec;
  }

  Suite read() const {
    const std::string text = read_text(file());
    const json j = parse_json_file_text(file(), text);
    only_keys(j, "", {"schema_version", "name", "description", "repetitions", "warmup", "threads", "timeout_s",
                      "memory_limit_mb", "max_steps", "seeds", "budget", "scenes", "algorithms"});
    if (!j.contains("schema_version") || j["schema_version"] != 1) fail("/schema_version", "expected 1");
    Suite s;
    s.file = file();
    s.hash = fmt::format("{:016x}", XXH3_64bits(text.data(), text.size()));
    s.name = j.value("name", fs::path(file()).stem().string());
    s.description = j.value("description", "");
    if (j.contains("repetitions")) s.repetitions = static_cast<int>(number(j["repetitions"], "/repetitions", 1, 1000));
    if (j.contains("warmup")) s.warmup = static_cast<int>(number(j["warmup"], "/warmup", 0, 100));
    if (j.contains("timeout_s")) s.timeout_s = number(j["timeout_s"], "/timeout_s", 0.001, 1e6);
    if (j.contains("memory_limit_mb"))
      s.memory_limit_bytes = static_cast<std::uint64_t>(number(j["memory_limit_mb"], "/memory_limit_mb", 64, 1e7)) << 20;
    const int threads = j.contains("threads") ? static_cast<int>(number(j["threads"], "/threads", 0, 1024)) : 0;
    const int max_steps = j.contains("max_steps") ? static_cast<int>(number(j["max_steps"], "/max_steps", 0, 1e9)) : 5000;
    std::vector<std::uint64_t> seeds = {1};
    if (j.contains("seeds")) {
      if (!j["seeds"].is_array() || j["seeds"].empty()) fail("/seeds", "expected a non-empty array of seeds");
      seeds.clear();
      for (std::size_t i = 0; i < j["seeds"].size(); ++i)
        seeds.push_back(static_cast<std::uint64_t>(number(j["seeds"][i], fmt::format("/seeds/{}", i), 0, 9e15)));
    }
    std::size_t budget_nodes = 0;
    double budget_length = 0.0;
    if (j.contains("budget")) {
      only_keys(j["budget"], "/budget", {"nodes", "length_m"});
      if (j["budget"].contains("nodes")) budget_nodes = static_cast<std::size_t>(number(j["budget"]["nodes"], "/budget/nodes", 0, 1e12));
      if (j["budget"].contains("length_m")) budget_length = number(j["budget"]["length_m"], "/budget/length_m", 0, 1e12);
    }

    struct SceneEntry {
      std::string spec, name;
      std::vector<std::string> params;
    };
    std::vector<SceneEntry> scenes;
    if (!j.contains("scenes") || !j["scenes"].is_array() || j["scenes"].empty()) fail("/scenes", "expected a non-empty array of scenes");
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
        if (e.contains("name")) se.name = e["name"].get<std::string>();
      }
      try {
        const Scene sc = load_scene(se.spec, se.params);
        if (se.name.empty()) se.name = sc.name;
      } catch (const InputError& err) {
        fail(path, err.what());
      }
      scenes.push_back(std::move(se));
    }

    struct AlgoEntry {
      std::string label, name, fault, leaf_obj;
      std::vector<std::string> params;
      std::vector<std::pair<std::string, std::vector<json>>> sweep;
      std::vector<json> points;  // explicit sweep points (instead of a product)
      [[nodiscard]] std::size_t count() const {
        if (!points.empty()) return points.size();
        std::size_t n = 1;
        for (const auto& [k, v] : sweep) n *= v.size();
        return n;
      }
    };
    std::vector<AlgoEntry> algos;
    if (!j.contains("algorithms") || !j["algorithms"].is_array() || j["algorithms"].empty())
      fail("/algorithms", "expected a non-empty array of algorithm entries");
    std::set<std::string> labels;
    for (std::size_t i = 0; i < j["algorithms"].size(); ++i) {
      const auto& e = j["algorithms"][i];
      const std::string path = fmt::format("/algorithms/{}", i);
      AlgoEntry a;
      if (e.is_string()) {
        a.name = e.get<std::string>();
      } else {
        only_keys(e, path, {"name", "label", "params", "sweep", "fault", "leaf_obj"});
        if (!e.contains("name") || !e["name"].is_string()) fail(path + "/name", "expected the algorithm's name");
        a.name = e["name"].get<std::string>();
        a.label = e.value("label", "");
        a.fault = e.value("fault", "");
        if (e.contains("leaf_obj")) {
          if (!e["leaf_obj"].is_string()) fail(path + "/leaf_obj", "expected the path of an OBJ file");
          a.leaf_obj = relative_to_suite(e["leaf_obj"].get<std::string>());
          try {
            (void)load_leaf_mesh(a.leaf_obj);
          } catch (const InputError& err) {
            fail(path + "/leaf_obj", err.what());
          }
        }
      }
      const AlgorithmEntry* entry = nullptr;
      try {
        entry = &find_algorithm(a.name);
      } catch (const InputError& err) {
        fail(path + "/name", err.what());
      }
      if (a.label.empty()) a.label = a.name;
      if (!labels.insert(a.label).second) fail(path + "/label", fmt::format("label '{}' is used twice; give each entry its own", a.label));
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
      if (e.is_object() && e.contains("sweep")) {
        const json& sw = e["sweep"];
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
      algos.push_back(std::move(a));
    }

    // Cells. Order: for each scene, seed and sweep point, every algorithm entry in turn (interleaved).
    std::size_t max_points = 1;
    for (const auto& a : algos) max_points = std::max(max_points, a.count());
    std::set<std::string> ids;
    for (const auto& sc : scenes)
      for (const auto seed : seeds)
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
            c.spec.threads = threads;
            c.spec.max_steps = max_steps;
            c.spec.budget_nodes = budget_nodes;
            c.spec.budget_length_m = budget_length;
            c.spec.fault = a.fault;
            c.spec.mesher.leaf_obj = a.leaf_obj;
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
    return s;
  }

 private:
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

const std::vector<std::string> kPhases = {"scene_load", "query_build", "growth", "meshing", "export", "metrics"};

std::string results_csv(const json& results) {
  std::vector<std::string> head = {"id", "label", "algorithm", "scene", "seed", "sweep", "repetition", "status"};
  for (const auto& ph : kPhases) {
    head.push_back(ph + "_wall_s");
    head.push_back(ph + "_cpu_s");
    head.push_back(ph + "_peak_rss_bytes");
    head.push_back(ph + "_alloc_count");
  }
  for (const auto& k : {"child_wall_s", "child_max_rss_bytes", "harness_overhead_s", "nodes", "leaves", "total_length_m",
                        "obj_bytes", "ply_bytes", "glb_bytes", "coverage", "attached_fraction", "penetration_nodes",
                        "geometry_hash"})
    head.emplace_back(k);
  std::string out = csv_row(head) + "\n";
  auto num = [](const json& j, const char* k) { return j.contains(k) ? j[k].dump() : std::string(); };
  for (const auto& t : results["trials"]) {
    for (const auto& s : t["samples"]) {
      std::vector<std::string> row = {t["id"], t["label"], t["algorithm"], t["scene"], t["seed"].dump(),
                                      t["sweep"].dump(), s["repetition"].dump(), s["status"]};
      for (const auto& ph : kPhases) {
        const json p = s.contains("phases") && s["phases"].contains(ph) ? s["phases"][ph] : json::object();
        row.push_back(num(p, "wall_s"));
        row.push_back(num(p, "cpu_s"));
        row.push_back(num(p, "peak_rss_bytes"));
        row.push_back(num(p, "alloc_count"));
      }
      const bool ok = s["status"] == "ok";
      const json m = ok && t.contains("metrics") ? t["metrics"] : json::object();
      const json b = ok && t.contains("output_bytes") ? t["output_bytes"] : json::object();
      row.push_back(num(s, "child_wall_s"));
      row.push_back(num(s, "child_max_rss_bytes"));
      row.push_back(num(s, "harness_overhead_s"));
      row.push_back(ok && t.contains("counts") ? t["counts"]["nodes"].dump() : "");
      row.push_back(ok && t.contains("counts") ? t["counts"]["leaves"].dump() : "");
      row.push_back(ok ? num(t, "total_length_m") : "");
      row.push_back(num(b, "obj"));
      row.push_back(num(b, "ply"));
      row.push_back(num(b, "glb"));
      row.push_back(num(m, "coverage"));
      row.push_back(num(m, "attached_fraction"));
      row.push_back(num(m, "penetration_nodes"));
      row.push_back(ok && t.contains("geometry_hash") ? t["geometry_hash"].get<std::string>() : "");
      out += csv_row(row) + "\n";
    }
  }
  return out;
}

// The per-cell fields taken from the first successful repetition's record.
const char* const kCellFields[] = {"geometry_hash", "counts",         "output_bytes", "metrics",   "total_length_m", "steps",
                                   "stopped_by",    "curve",          "params",       "algorithm_stats", "threads", "scene_hash",
                                   "alloc", "instructions"};

// Under callgrind a trial runs this many times slower; its timeout grows with it.
constexpr double kCallgrindSlowdown = 60.0;

// The per-phase instruction counts of a trial run under callgrind: every CALLGRIND_DUMP_STATS_AT(phase)
// wrote DIR/callgrind.out.N with "desc: Trigger: Client Request: PHASE" and "totals: IR". The files are
// removed once read (the final dump at program exit is not a phase).
json read_callgrind_phases(const fs::path& dir) {
  json out = json::object();
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

// Adds one finished repetition to its cell: the live run and the journal replay both come here.
// `cell` holds the record's per-cell fields (all of them for the cell's first success, else just the
// geometry hash and counts, which are compared to catch nondeterminism).
void apply_sample(json& t, const json& sample, const json& cell) {
  if (sample["status"] == "ok" && cell.is_object()) {
    if (!t.contains("geometry_hash")) {
      for (const char* k : kCellFields)
        if (cell.contains(k)) t[k] = cell[k];
    } else if (t["geometry_hash"] != cell["geometry_hash"] || t["counts"] != cell["counts"]) {
      t["nondeterministic"] = true;  // the same cell grew a different plant: report it loudly
    }
  }
  t["samples"].push_back(sample);
  std::string st = "ok";
  for (const auto& s : t["samples"])
    if (s["status"] != "ok") st = s["status"];
  t["status"] = st;
  if (st != "ok")
    for (const auto& s : t["samples"])
      if (s["status"] != "ok" && s.contains("message")) t["message"] = s["message"];
}

}  // namespace

Suite load_suite(const std::string& path) {
  if (!fs::exists(path)) throw InputError(fmt::format("{}: no such suite file", path));
  return SuiteReader(path).read();
}

// What a shard's context must share with the others for their timings to be compared: the machine type
// and the binary (its content hash, not the source tree's commit, which may move while shards run).
// Host names and dates may differ.
const char* const kMachineKeys[] = {"cpu_model", "hardware_threads", "binary_hash"};

json merge_results(const std::vector<json>& shards, const std::vector<std::string>& names, bool mixed_machines) {
  if (shards.empty()) throw InputError("merge: no shard results given");
  const json& first = shards.front();
  const int count = first.at("shard").value("count", 1);
  if (count < 1) throw InputError(fmt::format("{}: shard count {} (expected at least 1)", names[0], count));
  std::vector<std::size_t> slot(static_cast<std::size_t>(std::max(count, 1)), shards.size());  // shard index -> argument
  for (std::size_t k = 0; k < shards.size(); ++k) {
    const json& s = shards[k];
    if (s.value("kind", "") != "growbench-results")
      throw InputError(fmt::format("{}: not a growbench results file", names[k]));
    if (s.value("suite_hash", "") != first.value("suite_hash", ""))
      throw InputError(fmt::format("{}: a shard of another suite (suite_hash {} vs {} in {})", names[k], s.value("suite_hash", ""),
                                   first.value("suite_hash", ""), names[0]));
    if (s.value("repetitions", 0) != first.value("repetitions", 0))
      throw InputError(fmt::format("{}: {} repetitions, but {} has {}", names[k], s.value("repetitions", 0), names[0],
                                   first.value("repetitions", 0)));
    if (s.value("mode", "timing") != first.value("mode", "timing"))
      throw InputError(fmt::format("{}: mode '{}' differs from {}'s", names[k], s.value("mode", "timing"), names[0]));
    const int n = s.at("shard").value("count", 1), i = s.at("shard").value("index", 0);
    if (n != count) throw InputError(fmt::format("{}: shard of {} but {} is a shard of {}", names[k], n, names[0], count));
    if (i < 0 || i >= n) throw InputError(fmt::format("{}: shard index {} outside 0..{}", names[k], i, n - 1));
    if (slot[static_cast<std::size_t>(i)] != shards.size())
      throw InputError(fmt::format("{}: shard {}/{} given twice", names[k], i, n));
    slot[static_cast<std::size_t>(i)] = k;
  }
  std::vector<std::string> differ;
  const json none = json::object();
  const json& ctx0 = first.contains("context") ? first["context"] : none;
  for (std::size_t k = 1; k < shards.size(); ++k) {
    const json& ctx = shards[k].contains("context") ? shards[k]["context"] : none;
    for (const char* key : kMachineKeys)
      if (ctx.value(key, json()) != ctx0.value(key, json()))
        differ.push_back(fmt::format("{} {} in {} vs {} in {}", key, ctx.value(key, json()).dump(), names[k],
                                     ctx0.value(key, json()).dump(), names[0]));
  }
  if (!differ.empty() && !mixed_machines)
    throw InputError(fmt::format("merge: the shards ran on different machines or builds, so their timings cannot be compared "
                                 "({}); run every shard on identical nodes, or pass --mixed-machines to merge them marked as mixed",
                                 fmt::join(differ, "; ")));
  for (int i = 0; i < count; ++i)
    if (slot[static_cast<std::size_t>(i)] == shards.size()) throw InputError(fmt::format("merge: shard {}/{} is missing", i, count));
  // Cell k of the suite ran in shard k % count, as its (k / count)-th cell.
  json merged = first;
  merged["shard"] = {{"index", 0}, {"count", 1}};
  merged["trials"] = json::array();
  merged["shards"] = json::array();
  std::size_t total = 0;
  for (int i = 0; i < count; ++i) {
    const std::size_t a = slot[static_cast<std::size_t>(i)];
    merged["shards"].push_back({{"index", i}, {"file", names[a]}, {"context", shards[a].value("context", json::object())}});
    total += shards[a].at("trials").size();
  }
  for (std::size_t k = 0; k < total; ++k) {
    const json& trials = shards[slot[k % static_cast<std::size_t>(count)]].at("trials");
    const std::size_t at = k / static_cast<std::size_t>(count);
    if (at >= trials.size()) throw InputError(fmt::format("merge: shard {} has fewer cells than its suite gives it", k % count));
    merged["trials"].push_back(trials[at]);
  }
  if (!differ.empty()) merged["context"]["mixed_machines"] = true;
  merged.erase("renders");  // per-shard render summaries do not describe the merged grid
  return merged;
}

int run_trial_child(const TrialSpec& spec, const std::string& dir_name, int report_fd) {
  const fs::path dir(dir_name);
  auto write_error = [&](const std::string& msg) { std::ofstream(dir / "error.txt") << msg; };
  const auto started = std::chrono::steady_clock::now();
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
  } catch (const std::bad_alloc&) {
    write_error("out of memory (allocation refused under the address-space limit)");
    return kExitOom;
  } catch (const std::exception& e) {
    write_error(e.what());
    return kExitError;
  }
}

json trial_job(const SuiteConfig& c, const std::string& dir) {
  json spec = to_json(c.spec);
  spec["out_dir"] = dir;
  spec["context"] = false;
  spec["skip_teardown"] = true;
  return spec;
}

namespace {

int g_threads_at_fork = -1;  // in the process that started the launcher, when it did

}  // namespace

std::unique_ptr<Launcher> start_trial_launcher() {
  // Forking is only safe from a single-threaded parent. OpenVDB's logger, log4cplus, starts a pool of
  // worker threads when the library loads, before main: stop it (logging still works without it).
  log4cplus::deinitialize();
  // TBB's one-time initialisation (hardware topology; no worker threads: those start with the first
  // parallel algorithm) is done here once, so each forked trial inherits it instead of paying ~3 ms.
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

std::string run_suite(const Suite& suite_in, const SuiteRunOptions& o) {
  // Instruction counts: one repetition (they repeat exactly), no warm-up, one thread.
  Suite suite = suite_in;
  std::string valgrind, self_exe;
  if (o.instructions) {
    suite.repetitions = 1;
    suite.warmup = 0;
    for (auto& c : suite.configs) c.spec.threads = 1;
    valgrind = find_program("valgrind");
    if (valgrind.empty()) throw InputError("--instructions needs valgrind (Debian's valgrind package; scripts/install-deps)");
    self_exe = fs::read_symlink("/proc/self/exe").string();
  }
  const fs::path out = o.out_dir.empty() ? fs::path("out/suites") / suite.name : fs::path(o.out_dir);
  const fs::path results_path = out / "results.json";
  fs::create_directories(out / "trials");

  std::unique_ptr<Launcher> own_launcher;
  Launcher* launcher = o.launcher;
  if (!o.instructions && !launcher) {
    own_launcher = start_trial_launcher();
    launcher = own_launcher.get();
  }
  const ChildLimits limits{suite.timeout_s, suite.memory_limit_bytes};

  const fs::path journal_path = out / "journal.jsonl";
  json results;
  if (!o.resume && fs::exists(journal_path) && !fs::exists(results_path))
    throw InputError(fmt::format("{} holds a journal of an interrupted run: pass --resume to continue it, or another --out",
                                 journal_path.string()));
  if (fs::exists(results_path)) {
    if (!o.resume)
      throw InputError(fmt::format("{} already holds results: pass --resume to continue that run, or another --out",
                                   results_path.string()));
    try {
      results = json::parse(read_text(results_path.string()));
    } catch (const json::exception& e) {
      throw InputError(fmt::format("{}: cannot resume, the file is not valid results JSON ({})", results_path.string(), e.what()));
    }
    if (results.value("suite_hash", "") != suite.hash)
      throw InputError(fmt::format("{}: cannot resume, it was written for a different version of {}", results_path.string(), suite.file));
    if (results.value("repetitions", 0) != suite.repetitions)
      throw InputError(fmt::format("{}: cannot resume, it ran {} repetitions per cell and this run asks {}", results_path.string(),
                                   results.value("repetitions", 0), suite.repetitions));
  } else {
    results = {{"schema_version", 1},
               {"kind", "growbench-results"},
               {"mode", o.instructions ? "instructions" : "timing"},
               {"suite", {{"name", suite.name}, {"file", suite.file}, {"description", suite.description}}},
               {"suite_hash", suite.hash},
               {"repetitions", suite.repetitions},
               {"shard", {{"index", o.shard_index}, {"count", o.shard_count}}},
               {"trials", json::array()}};
  }
  // The context is taken in the parent before any trial.
  json ctx = run_context();
  ctx["suite_file_hash"] = suite.hash;
  if (g_threads_at_fork >= 0) ctx["parent_threads_at_fork"] = g_threads_at_fork;
  results["context"] = ctx;

  // Index the trials already recorded, and create entries for every cell of this shard.
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < results["trials"].size(); ++i) index[results["trials"][i]["id"]] = i;
  std::vector<const SuiteConfig*> cells;
  for (std::size_t i = 0; i < suite.configs.size(); ++i) {
    if (static_cast<int>(i % static_cast<std::size_t>(o.shard_count)) != o.shard_index) continue;
    const SuiteConfig& c = suite.configs[i];
    cells.push_back(&c);
    if (index.count(c.id)) continue;
    index[c.id] = results["trials"].size();
    results["trials"].push_back({{"id", c.id},
                                 {"label", c.label},
                                 {"algorithm", c.spec.algorithm},
                                 {"scene", c.scene_name},
                                 {"scene_spec", c.spec.scene},
                                 {"seed", c.spec.seed},
                                 {"sweep", c.sweep},
                                 {"spec", to_json(c.spec)},
                                 {"status", "pending"},
                                 {"samples", json::array()}});
  }

  // Replay the journal: repetitions finished after the last snapshot (or before a kill) come back.
  if (o.resume && fs::exists(journal_path)) {
    std::ifstream jin(journal_path);
    for (std::string line; std::getline(jin, line);) {
      json e;
      try {
        e = json::parse(line);
      } catch (const json::exception&) {
        continue;  // a line cut short by a kill: its trial runs again
      }
      const auto it = index.find(e.value("id", ""));
      if (it == index.end()) continue;
      json& t = results["trials"][it->second];
      bool have = false;
      for (const auto& smp : t["samples"]) have = have || smp["repetition"] == e["sample"]["repetition"];
      if (!have) apply_sample(t, e["sample"], e["cell"]);
    }
  }
  write_atomic(results_path, results.dump(1) + "\n");
  std::unique_ptr<FILE, int (*)(FILE*)> journal(std::fopen(journal_path.c_str(), "a"), &std::fclose);
  if (!journal) throw std::runtime_error(fmt::format("{}: cannot open the journal", journal_path.string()));
  auto last_snapshot = std::chrono::steady_clock::now();

  // Jobs: warm-ups, then repetitions, each pass over the interleaved cells.
  struct Job {
    const SuiteConfig* cell;
    int repetition;  // -1: warm-up
  };
  std::vector<Job> jobs;
  if (!cells.empty())
    for (int w = 0; w < suite.warmup; ++w) jobs.push_back({cells.front(), -1});
  for (int r = 0; r < suite.repetitions; ++r)
    for (const auto* c : cells) {
      bool done = false;
      for (const auto& s : results["trials"][index[c->id]]["samples"]) done = done || s["repetition"] == r;
      if (!done) jobs.push_back({c, r});
    }
  if (o.resume && jobs.size() == static_cast<std::size_t>(cells.empty() ? 0 : suite.warmup)) jobs.clear();

  const bool tty = isatty(STDERR_FILENO) != 0 && !o.quiet;
  const auto t_start = std::chrono::steady_clock::now();
  for (std::size_t jn = 0; jn < jobs.size(); ++jn) {
    const Job& job = jobs[jn];
    const SuiteConfig& c = *job.cell;
    const fs::path dir = out / "trials" / c.id;
    fs::create_directories(dir);
    if (!o.quiet) {
      const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
      const double eta = jn > 0 ? el / static_cast<double>(jn) * static_cast<double>(jobs.size() - jn) : 0.0;
      const std::string what = job.repetition < 0 ? "warm-up" : fmt::format("rep {}/{}", job.repetition + 1, suite.repetitions);
      const std::string line = fmt::format("[{}/{}] {} ({}){}", jn + 1, jobs.size(), c.id, what,
                                           jn > 0 ? fmt::format(", ETA {:.0f} s", eta) : std::string());
      if (tty) fmt::print(stderr, "\r{:<100}", line.substr(0, 100));
      else fmt::print(stderr, "{}\n", line);
    }
    const fs::path rec_path = dir / "record.json", err_path = dir / "error.txt";
    fs::remove(rec_path);
    fs::remove(err_path);
    const auto t0 = std::chrono::steady_clock::now();
    ChildResult cr;
    // What the child reports once record.json is in place (steady-clock ns), and the record itself,
    // read while the kernel is still tearing the child down.
    std::int64_t started_ns = 0, finished_ns = 0;
    json rec;
    std::string rec_error;
    double read_record_s = 0.0;
    auto read_record = [&] {
      const auto r0 = std::chrono::steady_clock::now();
      try {
        rec = json::parse(read_text(rec_path.string()));
      } catch (const std::exception& e) {
        rec = nullptr;
        rec_error = e.what();
      }
      read_record_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
    };
    if (o.instructions) {
      // Under callgrind: the trial runs in a fresh growbench process (`growbench trial`), single-threaded,
      // and dumps its instruction count at the end of every phase (harness/trial.cpp).
      write_atomic(dir / "spec.json", trial_job(c, dir.string()).dump() + "\n");
      for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().rfind("callgrind.out", 0) == 0) fs::remove(e.path());
      std::vector<std::string> args = {valgrind, "--tool=callgrind", "--callgrind-out-file=" + (dir / "callgrind.out").string(),
                                       // Ir do not depend on the cache model; it is pinned anyway, so a
                                       // run with --cache-sim=yes would be comparable across hosts.
                                       "--cache-sim=no", "--I1=32768,8,64", "--D1=32768,8,64", "--LL=8388608,16,64",
                                       "--instr-atstart=no",  // the trial turns it on per phase
                                       self_exe, "trial", (dir / "spec.json").string()};
      cr = run_program(args, "", {suite.timeout_s * kCallgrindSlowdown, 0}, (dir / "log.txt").string());
    } else {
      cr = launcher->run(trial_job(c, dir.string()).dump(), limits, [&](const std::string& report) {
        std::istringstream in(report);
        in >> started_ns >> finished_ns;
        read_record();
      });
    }
    const auto t_reaped = std::chrono::steady_clock::now();

    json sample = {{"repetition", job.repetition},
                   {"child_wall_s", cr.wall_s},
                   {"child_user_s", cr.user_s},
                   {"child_system_s", cr.system_s},
                   {"child_max_rss_bytes", cr.max_rss_bytes}};
    std::string status, message;
    if (cr.timed_out) {
      status = "timeout";
      message = fmt::format("killed after {} s", suite.timeout_s);
    } else if (cr.signal != 0) {
      // SIGKILL that we did not send is the kernel's OOM killer.
      status = cr.signal == SIGKILL ? "out_of_memory" : "crashed";
      message = signal_name(cr.signal);
    } else if (cr.exit_code == kExitOk && fs::exists(rec_path)) {
      if (rec.is_null() && rec_error.empty()) read_record();  // no report (callgrind trials)
      if (rec.is_null()) {
        status = "crashed";
        message = fmt::format("{} is unreadable: {}", rec_path.string(), rec_error);
      } else {
        status = "ok";
        if (o.instructions) {
          rec["instructions"] = read_callgrind_phases(dir);
          sample["instructions"] = rec["instructions"];
        }
      }
    } else {
      message = fs::exists(err_path) ? read_text(err_path.string()) : fmt::format("exit code {}", cr.exit_code);
      status = cr.exit_code == kExitInvalid ? "invalid_input" : cr.exit_code == kExitOom ? "out_of_memory" : "crashed";
    }
    sample["status"] = status;
    if (!message.empty()) sample["message"] = message;
    if (job.repetition < 0) continue;  // a warm-up: run, not kept
    json& t = results["trials"][index[c.id]];
    json cell = nullptr;
    if (status == "ok") {
      sample["phases"] = rec["phases"];
      double inside = 0.0;
      for (const auto& [k, v] : rec["phases"].items()) inside += v["wall_s"].get<double>();
      sample["steps"] = rec["steps"];
      cell = {{"geometry_hash", rec["geometry_hash"]}, {"counts", rec["counts"]}};
      if (!t.contains("geometry_hash")) {
        for (const char* k : kCellFields)
          if (rec.contains(k)) cell[k] = rec[k];
        cell["scene_hash"] = rec["scene"]["hash"];
        json alloc = json::object();
        for (const auto& [k, v] : rec["phases"].items()) alloc[k] = {{"count", v["alloc_count"]}, {"bytes", v["alloc_bytes"]}};
        cell["alloc"] = alloc;
      }
      // Where the time outside the phases goes (README, "Harness overhead"): fork to the child's start;
      // the child's own bookkeeping (measuring, record.json, snapshot); the kernel tearing the child down
      // (freeing its memory), during which this process reads the record; and this process's work.
      // Everything runs to just before the journal append below (one short write).
      const auto now = std::chrono::steady_clock::now();
      sample["outside_phases_s"] = std::chrono::duration<double>(now - t0).count() - inside;
      if (started_ns > 0) {
        const auto secs = [](std::chrono::steady_clock::time_point tp) { return std::chrono::duration<double>(tp.time_since_epoch()).count(); };
        const double started = 1e-9 * static_cast<double>(started_ns), finished = 1e-9 * static_cast<double>(finished_ns);
        const double launch = started - secs(t0), bookkeeping = finished - started - inside;
        const double parent = read_record_s + std::chrono::duration<double>(now - t_reaped).count();
        sample["launch_s"] = launch;
        sample["launch_fork_s"] = started - 1e-9 * static_cast<double>(cr.spawn_ns);
        sample["child_bookkeeping_s"] = bookkeeping;
        sample["teardown_s"] = secs(t_reaped) - finished;
        sample["parent_s"] = parent;
        sample["harness_overhead_s"] = launch + bookkeeping + parent;
      }
    }
    // The journal line is the durable record: appended and flushed before the next trial starts, so an
    // interrupted suite (even by kill -9) loses at most the trial in flight.
    const std::string line = json{{"id", c.id}, {"sample", sample}, {"cell", cell}}.dump() + "\n";
    if (std::fputs(line.c_str(), journal.get()) < 0 || std::fflush(journal.get()) != 0)
      throw std::runtime_error(fmt::format("{}: cannot append to the journal", (out / "journal.jsonl").string()));
    apply_sample(t, sample, cell);
    // Readable snapshots of the whole run every few seconds (always written atomically).
    if (std::chrono::steady_clock::now() - last_snapshot > std::chrono::seconds(10)) {
      write_atomic(results_path, results.dump(1) + "\n");
      write_atomic(out / "results.csv", results_csv(results));
      last_snapshot = std::chrono::steady_clock::now();
    }
  }
  write_atomic(results_path, results.dump(1) + "\n");
  write_atomic(out / "results.csv", results_csv(results));
  if (tty) fmt::print(stderr, "\r{:<100}\r", "");
  return results_path.string();
}

}  // namespace growbench
