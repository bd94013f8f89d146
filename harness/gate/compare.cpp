#include "harness/gate/compare.hpp"

#include <cmath>
#include <fstream>
#include <map>

#include <fmt/format.h>

#include "core/errors.hpp"

namespace growbench {
using json = nlohmann::json;

namespace {

std::string show(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) return fmt::format("{:.10g}", v.get<double>());
  return v.dump();
}

double ratio_of(const json& a, const json& b) {
  if (!a.is_number() || !b.is_number()) return 0.0;
  const double x = a.get<double>(), y = b.get<double>();
  return x != 0.0 ? y / x : (y == 0.0 ? 1.0 : 0.0);
}

// Keys of a (nested) object flattened to dotted paths.
void flatten(const json& j, const std::string& prefix, std::map<std::string, json>& out) {
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) flatten(v, prefix.empty() ? k : prefix + "." + k, out);
  } else {
    out[prefix] = j;
  }
}

const char* const kBehaviour[] = {"status", "geometry_hash", "counts", "metrics"};

}  // namespace

bool CompareResult::fails() const {
  if (!missing_cells.empty()) return true;
  for (const auto& c : changes)
    if (c.fails) return true;
  return false;
}

std::string CompareResult::table() const {
  std::string out;
  std::size_t wc = 4, wq = 8, wv = 3;
  for (const auto& c : changes) {
    wc = std::max(wc, c.cell.size());
    wq = std::max(wq, c.quantity.size());
    wv = std::max({wv, std::min<std::size_t>(c.old_value.size(), 24), std::min<std::size_t>(c.new_value.size(), 24)});
  }
  if (!changes.empty()) {
    out += fmt::format("{:<{}}  {:<{}}  {:>{}}  {:>{}}  {:>8}  {}\n", "cell", wc, "quantity", wq, "old", wv, "new", wv,
                       "new/old", "verdict");
    for (const auto& c : changes)
      out += fmt::format("{:<{}}  {:<{}}  {:>{}}  {:>{}}  {:>8}  {}\n", c.cell, wc, c.quantity, wq, c.old_value.substr(0, 24),
                         wv, c.new_value.substr(0, 24), wv, c.ratio > 0.0 ? fmt::format("{:.4f}", c.ratio) : "-",
                         c.fails ? "FAIL: " + c.why : c.why);
  }
  for (const auto& m : missing_cells) out += fmt::format("{}: in the base, missing from the new results (FAIL)\n", m);
  for (const auto& m : new_cells) out += fmt::format("{}: new cell, not in the base\n", m);
  if (small_changes > 0)
    out += fmt::format("{} instruction counts moved by less than 0.1% and fewer instructions than the floor (not listed)\n",
                       small_changes);
  if (!timings.empty()) {
    std::size_t wc2 = 4;
    for (const auto& t : timings) wc2 = std::max(wc2, t.cell.size());
    out += fmt::format("\nTimings (reported, not gated: a flag here is unconfirmed; `growbench ab` reruns and confirms)\n");
    out += fmt::format("{:<{}}  {:<14}  {:>7}  {:>10}  {:>10}  {:>24}  {:>8}  {}\n", "cell", wc2, "metric", "n", "old median",
                       "new median", "new/old [95% CI]", "p", "verdict");
    std::map<std::string, int> tally;
    for (const auto& t : timings) {
      const TimingVerdict& v = t.verdict;
      ++tally[v.verdict];
      out += fmt::format("{:<{}}  {:<14}  {:>7}  {:>10}  {:>10}  {:>24}  {:>8.2g}  {}\n", t.cell, wc2, t.metric,
                         fmt::format("{}/{}", v.n_a, v.n_b), format_seconds(v.median_a), format_seconds(v.median_b),
                         fmt::format("{:.3f} [{:.3f}, {:.3f}]", v.interval.ratio, v.interval.lo, v.interval.hi), v.test.p,
                         v.verdict == "inconclusive" ? fmt::format("inconclusive (~{} repetitions needed)", v.needed) : v.verdict);
    }
    std::string counts;
    for (const auto& [k, n] : tally) counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", n, k);
    out += "timings: " + counts + "\n\n";
  }
  std::size_t failing = 0;
  for (const auto& c : changes) failing += c.fails ? 1 : 0;
  out += fmt::format("{} cells compared, {} changed quantities, {} failing, {} missing cells: {}\n", cells_compared,
                     changes.size(), failing, missing_cells.size(), fails() ? "REGRESSION" : "OK");
  return out;
}

CompareResult compare_results(const json& base, const json& now, const CompareOptions& o) {
  CompareResult r;
  std::map<std::string, const json*> now_cells;
  for (const auto& t : now.at("trials")) now_cells[t.value("id", "")] = &t;
  std::map<std::string, bool> seen;
  for (const auto& b : base.at("trials")) {
    const std::string id = b.value("id", "");
    seen[id] = true;
    const auto it = now_cells.find(id);
    if (it == now_cells.end()) {
      r.missing_cells.push_back(id);
      continue;
    }
    const json& n = *it->second;
    ++r.cells_compared;
    auto compare_field = [&](const char* field, const std::string& why, bool fails) {
      std::map<std::string, json> fb, fn;
      if (b.contains(field)) flatten(b[field], field, fb);
      if (n.contains(field)) flatten(n[field], field, fn);
      for (const auto& [k, v] : fb) {
        const auto jt = fn.find(k);
        const json nv = jt == fn.end() ? json(nullptr) : jt->second;
        if (nv != v) r.changes.push_back({id, k, show(v), jt == fn.end() ? "(absent)" : show(nv), ratio_of(v, nv), fails, why});
      }
      for (const auto& [k, v] : fn)
        if (!fb.count(k)) r.changes.push_back({id, k, "(absent)", show(v), 0.0, false, "new quantity"});
    };
    for (const char* f : kBehaviour) compare_field(f, "behaviour", true);
    compare_field("output_bytes", "output bytes", true);
    // Allocation counts are deterministic for one thread; with more, libraries' parallel builders
    // (OpenVDB's level sets) allocate a varying amount, so they are shown but cannot fail.
    const bool single = b.value("threads", 0) == 1 && n.value("threads", 0) == 1;
    const std::size_t before = r.changes.size();
    compare_field("alloc", single ? "allocations" : "allocations (multithreaded: not gated)", single);
    for (std::size_t k = before; k < r.changes.size(); ++k) {
      Change& c = r.changes[k];
      const bool bytes = c.quantity.size() > 6 && c.quantity.compare(c.quantity.size() - 6, 6, ".bytes") == 0;
      if (c.fails && c.ratio > 0.0) {
        const double delta = std::abs(std::stod(c.new_value) - std::stod(c.old_value));
        const double slack = bytes ? o.alloc_bytes_slack : o.alloc_count_slack;
        if (delta <= slack) {
          c.fails = false;
          c.why = fmt::format("{} within {:g} (paths differ by checkout)", bytes ? "allocated bytes" : "allocations", slack);
        }
      }
    }
    // Instructions: a rise past the threshold fails; anything else is shown.
    if (b.contains("instructions") && n.contains("instructions")) {
      for (const auto& [phase, v] : b["instructions"].items()) {
        if (!n["instructions"].contains(phase)) continue;
        const json& nv = n["instructions"][phase];
        if (nv == v) continue;
        const double ratio = ratio_of(v, nv);
        if (std::abs(ratio - 1.0) < 1e-3 && std::abs(nv.get<double>() - v.get<double>()) < o.instructions_floor) {
          ++r.small_changes;  // heap-layout noise: counted, not listed
          continue;
        }
        const bool bad = ratio > 1.0 + o.instructions_threshold &&
                         nv.get<double>() - v.get<double>() > o.instructions_floor;
        r.changes.push_back({id, "instructions." + phase, show(v), show(nv), ratio, bad,
                             fmt::format("instructions {:+.2f}%{}", 100.0 * (ratio - 1.0),
                                         bad ? fmt::format(" > +{:g}%", 100.0 * o.instructions_threshold)
                                         : ratio > 1.0 + o.instructions_threshold ? " (below the floor)" : "")});
      }
    }
    // Timings: the repetitions of both runs, per phase, wall and CPU.
    auto samples = [](const json& t, const std::string& phase, const char* what) {
      std::vector<double> v;
      if (t.contains("samples"))
        for (const auto& s : t["samples"])
          if (s.value("status", "") == "ok" && s.contains("phases") && s["phases"].contains(phase))
            v.push_back(s["phases"][phase][what].get<double>());
      return v;
    };
    for (const char* phase : {"growth"})
      for (const char* what : {"wall_s", "cpu_s"}) {
        const auto a = samples(b, phase, what), c = samples(n, phase, what);
        if (a.size() >= 3 && c.size() >= 3)
          r.timings.push_back({id, fmt::format("{}.{}", phase, what), judge_timings(a, c, o.timing_effect, o.timing_alpha)});
      }
  }
  for (const auto& [id, t] : now_cells)
    if (!seen.count(id)) r.new_cells.push_back(id);
  return r;
}

json baseline_of(const json& results) {
  json b = {{"schema_version", 1}, {"kind", "growbench-baseline"}, {"mode", results.value("mode", "timing")}};
  if (results.contains("suite")) b["suite"] = results["suite"];
  if (results.contains("suite_hash")) b["suite_hash"] = results["suite_hash"];
  if (results.contains("context")) {
    const json& c = results["context"];
    json ctx = json::object();
    for (const char* k : {"growbench_commit", "dirty", "compiler", "cxx_flags", "build_type", "dependencies", "valgrind"})
      if (c.contains(k)) ctx[k] = c[k];
    b["context"] = ctx;
  }
  b["trials"] = json::array();
  for (const auto& t : results.at("trials")) {
    json cell = {{"id", t.value("id", "")}};
    for (const char* k : {"label", "algorithm", "scene", "seed", "status", "threads", "geometry_hash", "counts", "metrics",
                          "output_bytes", "alloc", "instructions"})
      if (t.contains(k)) cell[k] = t[k];
    b["trials"].push_back(cell);
  }
  return b;
}

json read_results_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open", path));
  json j;
  try {
    j = json::parse(in);
  } catch (const json::exception& e) {
    throw InputError(fmt::format("{}: not valid JSON: {}", path, e.what()));
  }
  const std::string kind = j.value("kind", "");
  if ((kind != "growbench-results" && kind != "growbench-baseline") || !j.contains("trials") || !j["trials"].is_array())
    throw InputError(fmt::format("{}: not a growbench results or baseline file (kind '{}')", path, kind));
  return j;
}

}  // namespace growbench
