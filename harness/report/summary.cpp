// `growbench summary`: per scene, a table of algorithm cells by metric, with medians and distribution-
// free 95% intervals for timings, and warnings where the repetitions are too noisy to trust.
#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "harness/report/columns.hpp"
#include "harness/report/summary.hpp"
#include "harness/stats/stats.hpp"

namespace growbench {
namespace {

using nlohmann::json;

// NAN for none: the tables print it as "-".
double median(std::vector<double> v) {
  return v.empty() ? NAN : median_of(std::move(v));
}

std::string si_bytes(double b) {
  if (!std::isfinite(b)) return "-";
  const char* u[] = {"B", "KiB", "MiB", "GiB"};
  int i = 0;
  while (b >= 1024.0 && i < 3) {
    b /= 1024.0;
    ++i;
  }
  return fmt::format("{:.1f} {}", b, u[i]);
}

// A cell's growth times as what they are: one trial, or the median of repetitions with the range of all
// of them (fewer than 6) or the distribution-free 95% interval of the median (6 or more).
std::string growth_text(const std::vector<double>& growth) {
  if (growth.empty()) return "-";
  if (growth.size() == 1) return fmt::format("{} (1 trial)", format_seconds(growth[0]));
  bool exact = false;
  const auto [lo, hi] = median_interval(growth, exact);
  return fmt::format("{} {} {}, {}", format_seconds(median(growth)), exact ? "CI" : "range", format_seconds(lo),
                     format_seconds(hi));
}

}  // namespace

namespace {

// A line on the machine's state when it may have slowed the run: a load average over a quarter of the
// hardware threads before the first trial (another process was working), and the clock and governor.
std::string machine_note(const RunContext& ctx) {
  std::string out;
  if (ctx.load_average_start && ctx.hardware_threads > 0 &&
      (*ctx.load_average_start)[0] > 0.25 * static_cast<double>(ctx.hardware_threads))
    out += wrap_text(fmt::format("Note: the machine was busy when the run began (load average {:.2f} over the last "
                                 "minute, on {} hardware threads): its timings may be slower and noisier than a quiet "
                                 "machine's.",
                                 (*ctx.load_average_start)[0], ctx.hardware_threads),
                     "", "");
  if (ctx.cpu_mhz || ctx.cpu_governor)
    out += fmt::format("Machine: {}{}{}; load average at the start {}, at the end {}.\n",
                       ctx.cpu_mhz ? fmt::format("{:.0f} MHz", *ctx.cpu_mhz) : "",
                       ctx.cpu_mhz && ctx.cpu_governor ? ", governor " : "", ctx.cpu_governor.value_or(""),
                       ctx.load_average_start ? fmt::format("{:.2f}", (*ctx.load_average_start)[0]) : "unknown",
                       ctx.load_average_end ? fmt::format("{:.2f}", (*ctx.load_average_end)[0]) : "unknown");
  return out;
}

// A scene's two tables, each within a terminal's width: how long each cell took and how much memory, then
// the plant it grew.
struct SceneTables {
  TextTable time{{"cell", "status", "verdict", "growth time", "total", "growth RSS"}, {}};
  TextTable plant{{"cell", "nodes", "length m", "PLY", "cover", "attach", "inside"}, {}};
};

// One cell's rows of its scene's tables; warnings about its repetitions go to `warnings`.
void cell_rows(const SuiteCell& t, SceneTables& tables, std::vector<std::string>& warnings) {
  const std::string& sc = t.scene;
  std::string cell = t.id;
  const auto slash = cell.find('/');
  cell = t.label + cell.substr(cell.find('/', slash + 1));  // label + /seed/sweep
  std::vector<double> growth, total, rss;
  for (const auto& s : t.samples) {
    if (s.status != "ok" || !s.phases) continue;
    const PhaseMeasures& g = s.phases->at[static_cast<std::size_t>(Phase::growth)].value();
    growth.push_back(g.wall_s);
    double tot = 0.0;
    s.phases->each([&](Phase p, const PhaseMeasures& v) {
      if (p != Phase::metrics) tot += v.wall_s;
    });
    total.push_back(tot);
    rss.push_back(static_cast<double>(g.peak_rss_bytes));
  }
  const double med = median(growth);
  const std::optional<TrialResults>& r = t.results.plant;
  const json m = r && r->metrics ? *r->metrics : json::object();
  auto metric = [&](const char* k) {
    // Open-ended in the file: null is a metric that does not apply; anything but a number (a hand-edited
    // file) shows as such.
    if (!m.contains(k)) return std::string("-");
    return m[k].is_null() ? std::string("n/a") : m[k].is_number() ? fmt::format("{:.3f}", m[k].get<double>()) : "?";
  };
  const std::string verdict = !r || !r->verdict                        ? "-"
                              : r->verdict->status == "not_applicable" ? "n/a"
                                                                       : r->verdict->status;
  tables.time.rows.push_back(
      {cell, t.status, verdict, growth_text(growth), format_seconds(median(total)), si_bytes(median(rss))});
  tables.plant.rows.push_back({cell, r ? std::to_string(r->counts.nodes) : "-",
                               r ? fmt::format("{:.2f}", r->total_length_m) : "-",
                               r && r->output_bytes.ply ? si_bytes(static_cast<double>(*r->output_bytes.ply)) : "-",
                               metric("coverage"), metric("attached_fraction"), metric("penetration_nodes")});
  if (r && r->verdict && !r->verdict->valid())
    warnings.push_back(fmt::format("{} on {}: {} ({}): left out of comparisons", cell, sc, verdict,
                                   fmt::join(r->verdict->reasons, "; ")));
  if (growth.size() >= 2) {
    double mean = 0.0, var = 0.0;
    for (const double g : growth) mean += g;
    mean /= static_cast<double>(growth.size());
    for (const double g : growth) var += (g - mean) * (g - mean);
    const double cv = std::sqrt(var / static_cast<double>(growth.size() - 1)) / mean;
    const double min_v = *std::min_element(growth.begin(), growth.end()),
                 max_v = *std::max_element(growth.begin(), growth.end());
    const double far = std::max(med - min_v, max_v - med) / med;
    if (cv > 0.10) warnings.push_back(fmt::format("{} on {}: growth time CV {:.0f}% > 10%", cell, sc, 100 * cv));
    if (far > 0.50)
      warnings.push_back(fmt::format("{} on {}: a repetition is {:.0f}% from the median (> 50%)", cell, sc, 100 * far));
  }
  if (t.nondeterministic.value_or(false))
    warnings.push_back(fmt::format("{} on {}: repetitions grew different plants", cell, sc));
  if (t.status != "ok")
    warnings.push_back(fmt::format("{} on {}: {} ({})", cell, sc, t.status, t.message.value_or("")));
}

// Where each trial's time outside its phases went (harness/suite/suite.cpp), medians over every sample.
std::string overhead_line(const ResultsFile& results) {
  std::map<std::string, std::vector<double>> over;
  for (const auto& t : results.trials)
    for (const auto& s : t.samples)
      for (const auto& [k, v] : {std::pair{"launch_s", &s.launch_s},
                                 {"child_bookkeeping_s", &s.child_bookkeeping_s},
                                 {"parent_s", &s.parent_s},
                                 {"harness_overhead_s", &s.harness_overhead_s},
                                 {"teardown_s", &s.teardown_s},
                                 {"outside_phases_s", &s.outside_phases_s}})
        if (*v) over[k].push_back(**v);
  if (over["harness_overhead_s"].empty()) return "";
  auto ms = [&](const char* k) { return fmt::format("{:.2f} ms", 1e3 * median(over[k])); };
  return wrap_text(
      fmt::format(
          "Harness overhead per trial, median of {} samples: {} (medians of its parts: launch {}, child bookkeeping "
          "{}, "
          "parent {}); then the kernel's teardown of the trial process {} (it grows with the trial's memory); outside "
          "the phases in all {}.",
          over["harness_overhead_s"].size(), ms("harness_overhead_s"), ms("launch_s"), ms("child_bookkeeping_s"),
          ms("parent_s"), ms("teardown_s"), ms("outside_phases_s")),
      "", "");
}

}  // namespace

std::string summarize_results(const ResultsFile& results) {
  std::string out;
  const RunContext& ctx = results.context;
  out += wrap_text(
      fmt::format("suite {} | commit {}{} | {} | {} hardware threads | {}", results.suite.name, ctx.growbench_commit,
                  ctx.dirty == "true" ? " (dirty)" : "", ctx.cpu_model, ctx.hardware_threads, ctx.date),
      "", "  ");
  std::vector<std::string> scene_order;
  std::map<std::string, std::vector<const SuiteCell*>> by_scene;
  for (const auto& t : results.trials) {
    if (!by_scene.count(t.scene)) scene_order.push_back(t.scene);
    by_scene[t.scene].push_back(&t);
  }
  out += machine_note(ctx);
  std::vector<std::string> warnings;
  for (const auto& sc : scene_order) {
    SceneTables tables;
    for (const SuiteCell* t : by_scene[sc]) cell_rows(*t, tables, warnings);
    out += '\n';
    out += wrap_text(fmt::format("== scene {}", sc), "", "   ");
    out += fmt::format("{}\n{}", tables.time.render(), tables.plant.render());
  }
  out += "\n";
  out += wrap_text(
      "Growth time: over a cell's repetitions, the median with the distribution-free 95% interval of the median "
      "('CI', from order statistics, 6 repetitions or more) or the range of all of them ('range', fewer); one "
      "trial is shown alone. Growth RSS: the growth phase's own peak resident memory (median). Verdicts other than "
      "valid are left out of comparisons across cells (docs/metrics.md, \"Validity\"); n/a: a metric that does "
      "not apply. Cover, attach, inside: the fraction of the surface covered, of nodes attached to it, and of "
      "nodes inside a solid (docs/metrics.md).",
      "", "");
  out += overhead_line(results);
  const auto noisy = static_cast<std::size_t>(std::count_if(warnings.begin(), warnings.end(), [](const std::string& w) {
    return w.find("growth time CV") != std::string::npos;
  }));
  if (4 * noisy > results.trials.size()) {
    out += '\n';
    out += wrap_text(fmt::format("Note: the growth times of {} of {} cells varied by more than 10% over their "
                                 "repetitions: this run's timings are noisy.",
                                 noisy, results.trials.size()),
                     "", "");
  }
  if (!warnings.empty()) {
    out += "\nWarnings:\n";
    for (const auto& w : warnings) out += wrap_text(w, "  ! ", "    ");
  }
  return out;
}

std::string summarize_results(const json& results) {
  return summarize_results(from_json<ResultsFile>(results, "the results"));
}

}  // namespace growbench
