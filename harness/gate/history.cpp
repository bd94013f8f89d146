#include "harness/gate/history.hpp"

#include <filesystem>
#include <map>
#include <vector>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/json_util.hpp"
#include "harness/gate/compare.hpp"
#include "harness/output/exporters.hpp"
#include "harness/report/report.hpp"
#include "harness/stats/stats.hpp"
#include "harness/record/files.hpp"

namespace growbench {
namespace fs = std::filesystem;
using nlohmann::json;

std::string history_machine(const json& context) {
  std::string m = fmt::format("{}-{}t", context.value("cpu_model", "unknown-cpu"), context.value("hardware_threads", 0));
  for (char& c : m) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  m = safe_name(m);
  // Runs of '_' from spaces and parentheses read badly in a path.
  std::string out;
  for (const char c : m)
    if (!(c == '_' && !out.empty() && out.back() == '_')) out += c;
  return out;
}

json history_entry(const json& results) {
  const json ctx = results.value("context", json::object());
  json cells = json::object();
  for (const auto& t : results.at("trials")) {
    json c = {{"status", t.value("status", "?")}};
    if (t.contains("geometry_hash")) c["geometry_hash"] = t["geometry_hash"];
    if (t.contains("counts")) c["nodes"] = t["counts"].value("nodes", 0);
    std::map<std::string, std::vector<double>> v;
    for (const auto& s : t.value("samples", json::array())) {
      if (s.value("status", "") != "ok" || !s.contains("phases")) continue;
      double total = 0.0;
      for (const auto& [k, p] : s["phases"].items())
        if (k != "metrics") total += p["wall_s"].get<double>();
      v["total_wall_s"].push_back(total);
      if (s["phases"].contains("growth")) {
        v["growth_wall_s"].push_back(s["phases"]["growth"]["wall_s"].get<double>());
        v["growth_cpu_s"].push_back(s["phases"]["growth"]["cpu_s"].get<double>());
        v["growth_peak_rss_bytes"].push_back(s["phases"]["growth"]["peak_rss_bytes"].get<double>());
      }
    }
    // Timings only from timing runs: under callgrind they are ~50x slower and mean nothing.
    if (results.value("mode", "timing") == "timing")
      for (const auto& [k, x] : v) {
        c[k] = median_of(x);
        c[k + "_n"] = x.size();
      }
    if (t.contains("instructions")) c["instructions"] = t["instructions"];
    cells[t.value("id", "?")] = c;
  }
  return {{"date", ctx.value("date", "")},
          {"mode", results.value("mode", "timing")},
          {"dirty", ctx.value("dirty", "unknown")},
          {"build_type", ctx.value("build_type", "")},
          {"cells", cells}};
}

std::string history_add(const std::string& results_path, const std::string& dir, const std::string& machine_in) {
  const json results = read_results_file(results_path);
  const json ctx = results.value("context", json::object());
  const std::string commit = ctx.value("growbench_commit", "");
  if (commit.empty() || commit == "unknown")
    throw InputError(fmt::format("{}: its context names no commit; a history is keyed by commit", results_path));
  const std::string machine = machine_in.empty() ? history_machine(ctx) : safe_name(machine_in);
  const std::string suite = safe_name(results.contains("suite") ? results["suite"].value("name", "suite") : "suite");
  const fs::path file = fs::path(dir) / machine / suite / (safe_name(commit) + ".json");
  json doc;
  if (fs::exists(file)) {
    try {
      doc = json::parse(read_text_file(file.string()));
    } catch (const json::exception& e) {
      throw InputError(fmt::format("{}: not a history file ({})", file.string(), e.what()));
    }
  } else {
    doc = {{"kind", "growbench-history"},
           {"schema_version", 1},
           {"commit", commit},
           {"commit_time", ctx.value("commit_time", json(nullptr))},
           {"machine", machine},
           {"cpu_model", ctx.value("cpu_model", "")},
           {"hardware_threads", ctx.value("hardware_threads", 0)},
           {"suite", suite},
           {"runs", json::array()}};
  }
  doc["runs"].push_back(history_entry(results));
  fs::create_directories(file.parent_path());
  const std::string text = doc.dump(1) + "\n";
  write_file_atomic(file.string(), text.data(), text.size());
  return file.string();
}

int history_plot(const std::string& dir, const std::string& out) {
  if (!fs::is_directory(dir)) throw InputError(fmt::format("{}: no such history directory", dir));
  return run_reports_script("history.py", {dir, "--out", out});
}

}  // namespace growbench
