// `growbench summary`: per scene, a table of algorithm cells by metric, with medians and distribution-
// free 95% intervals for timings, and warnings where the repetitions are too noisy to trust.
#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "harness/stats/stats.hpp"
#include "harness/report/summary.hpp"

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

}  // namespace

namespace {

// One cell's row of its scene's table; warnings about its repetitions go to `warnings`.
std::string cell_row(const SuiteCell& t, std::vector<std::string>& warnings) {
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
  bool exact = false;
  const auto [lo, hi] = median_interval(growth, exact);
  const double med = median(growth);
  const std::string ci = growth.empty() ? "-"
                                        : fmt::format("{} [{}{}, {}]", format_seconds(med), exact ? "" : "~",
                                                      format_seconds(lo), format_seconds(hi));
  const std::optional<TrialResults>& r = t.results.plant;
  const json m = r && r->metrics ? *r->metrics : json::object();
  auto metric = [&](const char* k) {
    // Metrics are open-ended in the file: a value that is not a number (a hand-edited file) shows as such.
    return !m.contains(k) ? std::string("-") : m[k].is_number() ? fmt::format("{:.3f}", m[k].get<double>()) : "?";
  };
  std::string row =
      fmt::format("{:<40} {:>6} {:>30} {:>10} {:>11} {:>8} {:>9} {:>10} {:>8} {:>8} {:>8}\n", cell.substr(0, 40),
                  t.status, ci, format_seconds(median(total)), si_bytes(median(rss)),
                  r ? std::to_string(r->counts.nodes) : "-", r ? fmt::format("{:.2f}", r->total_length_m) : "-",
                  r && r->output_bytes.ply ? si_bytes(static_cast<double>(*r->output_bytes.ply)) : "-",
                  metric("coverage"), metric("attached_fraction"), metric("penetration_nodes"));
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
  return row;
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
  return fmt::format(
      "Harness overhead per trial, median of {} samples: {} (medians of its parts: launch {}, child bookkeeping {}, "
      "parent {}); then the kernel's teardown of the trial process {} (it grows with the trial's memory); outside "
      "the phases in all {}.\n",
      over["harness_overhead_s"].size(), ms("harness_overhead_s"), ms("launch_s"), ms("child_bookkeeping_s"),
      ms("parent_s"), ms("teardown_s"), ms("outside_phases_s"));
}

}  // namespace

std::string summarize_results(const ResultsFile& results) {
  std::string out;
  const RunContext& ctx = results.context;
  out +=
      fmt::format("suite {} | commit {}{} | {} | {} hardware threads | {}\n", results.suite.name, ctx.growbench_commit,
                  ctx.dirty == "true" ? " (dirty)" : "", ctx.cpu_model, ctx.hardware_threads, ctx.date);
  std::vector<std::string> scene_order;
  std::map<std::string, std::vector<const SuiteCell*>> by_scene;
  for (const auto& t : results.trials) {
    if (!by_scene.count(t.scene)) scene_order.push_back(t.scene);
    by_scene[t.scene].push_back(&t);
  }
  std::vector<std::string> warnings;
  for (const auto& sc : scene_order) {
    out += fmt::format("\n== scene {}\n", sc);
    out += fmt::format("{:<40} {:>6} {:>30} {:>10} {:>11} {:>8} {:>9} {:>10} {:>8} {:>8} {:>8}\n", "cell", "status",
                       "growth median [95% CI]", "total", "peak RSS", "nodes", "length m", "PLY", "cover", "attach",
                       "inside");
    for (const SuiteCell* t : by_scene[sc]) out += cell_row(*t, warnings);
  }
  out +=
      "\nIntervals: distribution-free 95% CI of the median from order statistics ('~': fewer than 6 repetitions, full "
      "range shown).\n";
  out += overhead_line(results);
  if (!warnings.empty()) {
    out += "\nWarnings:\n";
    for (const auto& w : warnings) out += "  ! " + w + "\n";
  }
  return out;
}

std::string summarize_results(const json& results) {
  return summarize_results(from_json<ResultsFile>(results, "the results"));
}

}  // namespace growbench
