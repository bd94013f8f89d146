#include "harness/gate/compare.hpp"

#include <cmath>
#include <map>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "harness/record/files.hpp"
#include "harness/record/reflect.hpp"

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

}  // namespace

bool CompareResult::fails() const {
  if (!missing_cells.empty()) return true;
  for (const auto& c : changes)
    if (c.fails) return true;
  return false;
}

std::string CompareResult::table() const {
  // The verdict first, so that it is read before the rows; it closes the output again for a log's tail.
  std::size_t failing = 0;
  for (const auto& c : changes) failing += c.fails ? 1 : 0;
  const std::string verdict =
      fmt::format("{} cells compared, {} changed quantities, {} failing, {} missing cells: {}\n", cells_compared,
                  changes.size(), failing, missing_cells.size(), fails() ? "REGRESSION" : "OK");
  std::string out = verdict;
  for (const auto& n : plugin_notes) out += n + "\n";
  if (!changes.empty() || !missing_cells.empty() || !new_cells.empty() || small_changes > 0 || !timings.empty())
    out += "\n";
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
      out += fmt::format("{:<{}}  {:<{}}  {:>{}}  {:>{}}  {:>8}  {}\n", c.cell, wc, c.quantity, wq,
                         c.old_value.substr(0, 24), wv, c.new_value.substr(0, 24), wv,
                         c.ratio > 0.0 ? fmt::format("{:.4f}", c.ratio) : "-", c.fails ? "FAIL: " + c.why : c.why);
  }
  for (const auto& m : missing_cells) out += fmt::format("{}: in the base, missing from the new results (FAIL)\n", m);
  for (const auto& m : new_cells) out += fmt::format("{}: new cell, not in the base\n", m);
  if (small_changes > 0)
    out += fmt::format(
        "{} instruction counts moved by less than 0.1% and fewer instructions than the floor (not listed)\n",
        small_changes);
  if (!timings.empty()) {
    std::size_t wc2 = 4;
    for (const auto& t : timings) wc2 = std::max(wc2, t.cell.size());
    out += fmt::format(
        "\nTimings (reported, not gated: a flag here is unconfirmed; `growbench ab` reruns and confirms)\n");
    out += fmt::format("{:<{}}  {:<14}  {:>7}  {:>10}  {:>10}  {:>24}  {:>8}  {}\n", "cell", wc2, "metric", "n",
                       "old median", "new median", "new/old [95% CI]", "p", "verdict");
    std::map<std::string, int> tally;
    for (const auto& t : timings) {
      const TimingVerdict& v = t.verdict;
      ++tally[v.verdict];
      out += fmt::format(
          "{:<{}}  {:<14}  {:>7}  {:>10}  {:>10}  {:>24}  {:>8.2g}  {}\n", t.cell, wc2, t.metric,
          fmt::format("{}/{}", v.n_a, v.n_b), format_seconds(v.median_a), format_seconds(v.median_b),
          fmt::format("{:.3f} [{:.3f}, {:.3f}]", v.interval.ratio, v.interval.lo, v.interval.hi), v.test.p,
          v.verdict == "inconclusive" ? fmt::format("inconclusive (~{} repetitions needed)", v.needed) : v.verdict);
    }
    std::string counts;
    for (const auto& [k, n] : tally) counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", n, k);
    out += "timings: " + counts + "\n\n";
  }
  if (out.size() > verdict.size()) out += verdict;
  return out;
}

namespace {

// A cell as the gate sees it, from either kind of file: what a baseline keeps, and the repetitions when the
// file is a results file.
struct GateCell {
  BaselineCell cell;
  const std::vector<SuiteSample>* samples = nullptr;
};

const std::vector<PluginOrigin>& plugins_of(const GateFile& f) {
  if (const auto* r = std::get_if<ResultsFile>(&f)) return r->context.plugins;
  return std::get<Baseline>(f).context.plugins;
}

// What differs between the plugins two runs loaded, by algorithm name: a plugin that is another build (its
// file's hash) or another ABI or version, or that only one side loaded. A note, not a failure: the cells say
// whether the plants changed.
std::vector<std::string> plugin_notes(const GateFile& base, const GateFile& now) {
  std::vector<std::string> notes;
  std::map<std::string, const PluginOrigin*> after;
  for (const auto& p : plugins_of(now)) after[p.name] = &p;
  for (const auto& b : plugins_of(base)) {
    const auto it = after.find(b.name);
    if (it == after.end()) {
      notes.push_back(
          fmt::format("plugin {}: loaded in the base ({}, xxh3 {}), not in the new results", b.name, b.path, b.hash));
      continue;
    }
    const PluginOrigin& n = *it->second;
    if (n.hash != b.hash || n.abi_version != b.abi_version || n.version != b.version)
      notes.push_back(
          fmt::format("plugin {}: another build: base {} (version {}, ABI {}, xxh3 {}), new {} (version {}, "
                      "ABI {}, xxh3 {})",
                      b.name, b.path, b.version, b.abi_version, b.hash, n.path, n.version, n.abi_version, n.hash));
    after.erase(it);
  }
  for (const auto& [name, n] : after)
    notes.push_back(
        fmt::format("plugin {}: loaded in the new results ({}, xxh3 {}), not in the base", name, n->path, n->hash));
  return notes;
}

std::vector<GateCell> gate_cells(const GateFile& f) {
  std::vector<GateCell> out;
  if (const auto* r = std::get_if<ResultsFile>(&f)) {
    for (const auto& t : r->trials) out.push_back({baseline_cell_of(t), &t.samples});
  } else {
    for (const auto& c : std::get<Baseline>(f).trials) out.push_back({c, nullptr});
  }
  return out;
}

template <class T>
std::optional<json> json_of(const std::optional<T>& v) {
  if (!v) return std::nullopt;
  if constexpr (requires { to_json(*v); })
    return to_json(*v);
  else
    return json(*v);
}

// The fields compared quantity by quantity ("counts.nodes"), each as JSON (absent: the cell has none).
struct GatedField {
  const char* name;
  std::optional<json> (*get)(const BaselineCell&);
};
const GatedField kBehaviour[] = {
    {"status", [](const BaselineCell& c) { return std::optional<json>(c.status); }},
    {"geometry_hash", [](const BaselineCell& c) { return json_of(c.geometry_hash); }},
    {"counts", [](const BaselineCell& c) { return json_of(c.counts); }},
    {"metrics", [](const BaselineCell& c) { return json_of(c.metrics); }},
    {"verdict", [](const BaselineCell& c) { return json_of(c.verdict); }},
};
const GatedField kOutputBytes = {"output_bytes", [](const BaselineCell& c) { return json_of(c.output_bytes); }};
const GatedField kAlloc = {"alloc", [](const BaselineCell& c) { return json_of(c.alloc); }};

// Every changed instruction count: a rise past the threshold fails; anything else is shown.
void compare_instructions(const std::string& id, const InstructionCounts& base, const InstructionCounts& now,
                          const CompareOptions& o, CompareResult& r) {
  base.each([&](Phase phase, std::uint64_t old_ir) {
    const std::uint64_t* new_ir = now.find(phase);
    if (!new_ir || *new_ir == old_ir) return;
    const json v = old_ir, nv = *new_ir;
    const double ratio = ratio_of(v, nv);
    const double delta = static_cast<double>(*new_ir) - static_cast<double>(old_ir);
    if (std::abs(ratio - 1.0) < 1e-3 && std::abs(delta) < o.instructions_floor) {
      ++r.small_changes;  // heap-layout noise: counted, not listed
      return;
    }
    const bool bad = ratio > 1.0 + o.instructions_threshold && delta > o.instructions_floor;
    r.changes.push_back({id, fmt::format("instructions.{}", phase_name(phase)), show(v), show(nv), ratio, bad,
                         fmt::format("instructions {:+.2f}%{}", 100.0 * (ratio - 1.0),
                                     bad ? fmt::format(" > +{:g}%", 100.0 * o.instructions_threshold)
                                     : ratio > 1.0 + o.instructions_threshold ? " (below the floor)"
                                                                              : "")});
  });
}

// The repetitions of both runs, per phase, wall and CPU: judged when both have at least 3.
void compare_timings(const GateCell& b, const GateCell& n, const CompareOptions& o, CompareResult& r) {
  auto samples = [](const GateCell& t, Phase phase, bool cpu) {
    std::vector<double> v;
    if (t.samples)
      for (const auto& s : *t.samples)
        if (const PhaseMeasures* p = s.status == "ok" && s.phases ? s.phases->find(phase) : nullptr)
          v.push_back(cpu ? p->cpu_s : p->wall_s);
    return v;
  };
  for (const Phase phase : {Phase::growth})
    for (const bool cpu : {false, true}) {
      const auto a = samples(b, phase, cpu), c = samples(n, phase, cpu);
      if (a.size() >= 3 && c.size() >= 3)
        r.timings.push_back({b.cell.id, fmt::format("{}.{}", phase_name(phase), cpu ? "cpu_s" : "wall_s"),
                             judge_timings(a, c, o.timing_effect, o.timing_alpha)});
    }
}

void compare_cell(const GateCell& gb, const GateCell& gn, const CompareOptions& o, CompareResult& r) {
  const BaselineCell& b = gb.cell;
  const BaselineCell& n = gn.cell;
  const std::string& id = b.id;
  auto compare_field = [&](const GatedField& field, const std::string& why, bool fails) {
    std::map<std::string, json> fb, fn;
    if (const auto v = field.get(b)) flatten(*v, field.name, fb);
    if (const auto v = field.get(n)) flatten(*v, field.name, fn);
    for (const auto& [k, v] : fb) {
      const auto jt = fn.find(k);
      const json nv = jt == fn.end() ? json(nullptr) : jt->second;
      if (nv != v)
        r.changes.push_back({id, k, show(v), jt == fn.end() ? "(absent)" : show(nv), ratio_of(v, nv), fails, why});
    }
    for (const auto& [k, v] : fn)
      if (!fb.count(k)) r.changes.push_back({id, k, "(absent)", show(v), 0.0, false, "new quantity"});
  };
  for (const auto& f : kBehaviour) compare_field(f, "behaviour", true);
  compare_field(kOutputBytes, "output bytes", true);
  // Allocation counts are deterministic for one thread; with more, libraries' parallel builders
  // (OpenVDB's level sets) allocate a varying amount, so they are shown but cannot fail.
  const bool single = b.threads.value_or(0) == 1 && n.threads.value_or(0) == 1;
  const std::size_t before = r.changes.size();
  compare_field(kAlloc, single ? "allocations" : "allocations (multithreaded: not gated)", single);
  for (std::size_t k = before; k < r.changes.size(); ++k) {
    Change& c = r.changes[k];
    const bool bytes = c.quantity.size() > 6 && c.quantity.compare(c.quantity.size() - 6, 6, ".bytes") == 0;
    if (c.fails && c.ratio > 0.0) {
      const double delta = std::abs(std::stod(c.new_value) - std::stod(c.old_value));
      const double slack = bytes ? o.alloc_bytes_slack : o.alloc_count_slack;
      if (delta <= slack) {
        c.fails = false;
        c.why =
            fmt::format("{} within {:g} (paths differ by checkout)", bytes ? "allocated bytes" : "allocations", slack);
      }
    }
  }
  if (b.instructions && n.instructions) compare_instructions(id, *b.instructions, *n.instructions, o, r);
  compare_timings(gb, gn, o, r);
}

// A results or baseline document read as JSON from `source`.
GateFile gate_file_from_json(const json& j, const std::string& source) {
  const json* kind = j.is_object() && j.contains("kind") ? &j["kind"] : nullptr;
  if (kind && *kind == kBaselineKind) return baseline_from_json(j, source);
  if (kind && *kind == kResultsKind) return results_from_json(j, source);
  throw InputError(fmt::format("{}: not a growbench results or baseline file (kind {}, expected '{}' or '{}')", source,
                               kind ? kind->dump() : "absent", kResultsKind, kBaselineKind));
}

}  // namespace

CompareResult compare_results(const GateFile& base, const GateFile& now, const CompareOptions& o) {
  CompareResult r;
  const std::vector<GateCell> base_cells = gate_cells(base), now_list = gate_cells(now);
  std::map<std::string, const GateCell*> now_cells;
  for (const auto& t : now_list) now_cells[t.cell.id] = &t;
  std::map<std::string, bool> seen;
  for (const auto& b : base_cells) {
    seen[b.cell.id] = true;
    const auto it = now_cells.find(b.cell.id);
    if (it == now_cells.end()) {
      r.missing_cells.push_back(b.cell.id);
      continue;
    }
    ++r.cells_compared;
    compare_cell(b, *it->second, o, r);
  }
  for (const auto& [id, t] : now_cells)
    if (!seen.count(id)) r.new_cells.push_back(id);
  r.plugin_notes = plugin_notes(base, now);
  return r;
}

CompareResult compare_results(const json& base, const json& now, const CompareOptions& o) {
  return compare_results(gate_file_from_json(base, "the base"), gate_file_from_json(now, "the new results"), o);
}

Baseline baseline_of(const ResultsFile& results) {
  Baseline b;
  b.mode = results.mode;
  b.suite = results.suite;
  b.suite_hash = results.suite_hash;
  const RunContext& c = results.context;  // the fields of its context a baseline keeps
  project(c, b.context);
  for (const auto& t : results.trials) b.trials.push_back(baseline_cell_of(t));
  return b;
}

json baseline_of(const json& results) {
  return to_json(baseline_of(from_json<ResultsFile>(results, "the results")));
}

GateFile read_gate_file(const std::string& path) {
  return gate_file_from_json(read_json_file(path), path);
}

}  // namespace growbench
