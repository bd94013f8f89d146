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
double median(std::vector<double> v) { return v.empty() ? NAN : median_of(std::move(v)); }

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

std::string summarize_results(const json& results) {
  std::string out;
  const json ctx = results.value("context", json::object());
  out += fmt::format("suite {} | commit {}{} | {} | {} hardware threads | {}\n",
                     results["suite"].value("name", "?"), ctx.value("growbench_commit", "?"),
                     ctx.value("dirty", "") == "true" ? " (dirty)" : "", ctx.value("cpu_model", "?"),
                     ctx.value("hardware_threads", 0), ctx.value("date", "?"));
  std::vector<std::string> scene_order;
  std::map<std::string, std::vector<const json*>> by_scene;
  for (const auto& t : results["trials"]) {
    const std::string sc = t["scene"];
    if (!by_scene.count(sc)) scene_order.push_back(sc);
    by_scene[sc].push_back(&t);
  }
  std::vector<std::string> warnings;
  for (const auto& sc : scene_order) {
    out += fmt::format("\n== scene {}\n", sc);
    out += fmt::format("{:<40} {:>6} {:>30} {:>10} {:>11} {:>8} {:>9} {:>10} {:>8} {:>8} {:>8}\n", "cell", "status",
                       "growth median [95% CI]", "total", "peak RSS", "nodes", "length m", "PLY", "cover", "attach",
                       "inside");
    for (const json* tp : by_scene[sc]) {
      const json& t = *tp;
      std::string cell = t["id"].get<std::string>();
      const auto slash = cell.find('/');
      cell = t["label"].get<std::string>() + cell.substr(cell.find('/', slash + 1));  // label + /seed/sweep
      std::vector<double> growth, total, rss;
      for (const auto& s : t["samples"]) {
        if (s["status"] != "ok") continue;
        growth.push_back(s["phases"]["growth"]["wall_s"].get<double>());
        double tot = 0.0;
        for (const auto& [k, v] : s["phases"].items())
          if (k != "metrics") tot += v["wall_s"].get<double>();
        total.push_back(tot);
        rss.push_back(s["phases"]["growth"]["peak_rss_bytes"].get<double>());
      }
      bool exact = false;
      const auto [lo, hi] = median_interval(growth, exact);
      const double med = median(growth);
      const std::string ci = growth.empty() ? "-" : fmt::format("{} [{}{}, {}]", format_seconds(med), exact ? "" : "~", format_seconds(lo), format_seconds(hi));
      const json m = t.value("metrics", json::object());
      auto metric = [&](const char* k) { return m.contains(k) ? fmt::format("{:.3f}", m[k].get<double>()) : std::string("-"); };
      out += fmt::format("{:<40} {:>6} {:>30} {:>10} {:>11} {:>8} {:>9} {:>10} {:>8} {:>8} {:>8}\n", cell.substr(0, 40),
                         t.value("status", "?"), ci, format_seconds(median(total)), si_bytes(median(rss)),
                         t.contains("counts") ? std::to_string(t["counts"]["nodes"].get<long>()) : "-",
                         t.contains("total_length_m") ? fmt::format("{:.2f}", t["total_length_m"].get<double>()) : "-",
                         t.contains("output_bytes") && t["output_bytes"].contains("ply") ? si_bytes(t["output_bytes"]["ply"].get<double>()) : "-",
                         metric("coverage"), metric("attached_fraction"), metric("penetration_nodes"));
      if (growth.size() >= 2) {
        double mean = 0.0, var = 0.0;
        for (const double g : growth) mean += g;
        mean /= static_cast<double>(growth.size());
        for (const double g : growth) var += (g - mean) * (g - mean);
        const double cv = std::sqrt(var / static_cast<double>(growth.size() - 1)) / mean;
        const double min_v = *std::min_element(growth.begin(), growth.end()), max_v = *std::max_element(growth.begin(), growth.end());
        const double far = std::max(med - min_v, max_v - med) / med;
        if (cv > 0.10) warnings.push_back(fmt::format("{} on {}: growth time CV {:.0f}% > 10%", cell, sc, 100 * cv));
        if (far > 0.50) warnings.push_back(fmt::format("{} on {}: a repetition is {:.0f}% from the median (> 50%)", cell, sc, 100 * far));
      }
      if (t.value("nondeterministic", false)) warnings.push_back(fmt::format("{} on {}: repetitions grew different plants", cell, sc));
      if (t.value("status", "ok") != "ok")
        warnings.push_back(fmt::format("{} on {}: {} ({})", cell, sc, t.value("status", "?"), t.value("message", "")));
    }
  }
  out += "\nIntervals: distribution-free 95% CI of the median from order statistics ('~': fewer than 6 repetitions, full range shown).\n";
  // Where each trial's time outside its phases went (harness/suite.cpp), medians over every ok sample.
  std::map<std::string, std::vector<double>> over;
  for (const auto& t : results["trials"])
    for (const auto& s : t["samples"])
      for (const char* k : {"launch_s", "child_bookkeeping_s", "parent_s", "harness_overhead_s", "teardown_s", "outside_phases_s"})
        if (s.contains(k)) over[k].push_back(s[k].get<double>());
  if (!over["harness_overhead_s"].empty()) {
    auto ms = [&](const char* k) { return fmt::format("{:.2f} ms", 1e3 * median(over[k])); };
    out += fmt::format(
        "Harness overhead per trial, median of {} samples: {} (medians of its parts: launch {}, child bookkeeping {}, "
        "parent {}); then the kernel's teardown of the trial process {} (it grows with the trial's memory); outside "
        "the phases in all {}.\n",
        over["harness_overhead_s"].size(), ms("harness_overhead_s"), ms("launch_s"), ms("child_bookkeeping_s"),
        ms("parent_s"), ms("teardown_s"), ms("outside_phases_s"));
  }
  if (!warnings.empty()) {
    out += "\nWarnings:\n";
    for (const auto& w : warnings) out += "  ! " + w + "\n";
  }
  return out;
}

}  // namespace growbench
