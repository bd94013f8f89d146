#include "harness/gate/history.hpp"

#include <filesystem>
#include <map>
#include <vector>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "harness/report/report.hpp"
#include "harness/stats/stats.hpp"
#include "harness/record/files.hpp"

namespace growbench {
namespace fs = std::filesystem;

std::string history_machine(const RunContext& context) {
  std::string m =
      fmt::format("{}-{}t", context.cpu_model.empty() ? "unknown-cpu" : context.cpu_model, context.hardware_threads);
  for (char& c : m) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  m = safe_name(m);
  // Runs of '_' from spaces and parentheses read badly in a path.
  std::string out;
  for (const char c : m)
    if (!(c == '_' && !out.empty() && out.back() == '_')) out += c;
  return out;
}

namespace {

HistoryCell history_cell(const SuiteCell& t, bool timing) {
  HistoryCell c;
  c.status = t.status;
  if (const auto& plant = t.results.plant) {
    c.geometry_hash = plant->geometry_hash;
    c.nodes = plant->counts.nodes;
  }
  std::vector<double> total, growth_wall, growth_cpu, growth_rss;
  for (const auto& s : t.samples) {
    if (s.status != "ok" || !s.phases) continue;
    double sum = 0.0;
    s.phases->each([&](Phase phase, const PhaseMeasures& p) {
      if (phase != Phase::metrics) sum += p.wall_s;
    });
    total.push_back(sum);
    if (const PhaseMeasures* g = s.phases->find(Phase::growth)) {
      growth_wall.push_back(g->wall_s);
      growth_cpu.push_back(g->cpu_s);
      growth_rss.push_back(static_cast<double>(g->peak_rss_bytes));
    }
  }
  // Timings only from timing runs: under callgrind they are many times slower and mean nothing.
  auto keep = [&](std::optional<double>& median, std::optional<std::uint64_t>& n, const std::vector<double>& x) {
    if (!timing || x.empty()) return;
    median = median_of(x);
    n = x.size();
  };
  keep(c.total_wall_s, c.total_wall_s_n, total);
  keep(c.growth_wall_s, c.growth_wall_s_n, growth_wall);
  keep(c.growth_cpu_s, c.growth_cpu_s_n, growth_cpu);
  keep(c.growth_peak_rss_bytes, c.growth_peak_rss_bytes_n, growth_rss);
  c.instructions = t.results.instructions;
  return c;
}

}  // namespace

HistoryRun history_entry(const ResultsFile& results) {
  const RunContext& ctx = results.context;
  HistoryRun run{ctx.date, results.mode, ctx.dirty, ctx.build_type, {}};
  for (const auto& t : results.trials) run.cells[t.id] = history_cell(t, results.mode == "timing");
  return run;
}

std::string history_add(const std::string& results_path, const std::string& dir, const std::string& machine_in) {
  const ResultsFile results = read_results(results_path);
  const RunContext& ctx = results.context;
  const std::string commit = ctx.growbench_commit;
  if (commit.empty() || commit == "unknown")
    throw InputError(fmt::format("{}: its context names no commit; a history is keyed by commit", results_path));
  const std::string machine = machine_in.empty() ? history_machine(ctx) : safe_name(machine_in);
  const std::string suite = safe_name(results.suite.name.empty() ? "suite" : results.suite.name);
  const fs::path file = fs::path(dir) / machine / suite / (safe_name(commit) + ".json");
  HistoryFile doc;
  if (fs::exists(file)) {
    try {
      doc = read_history_file(file.string());
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: not a history file ({})", file.string(), e.what()));
    }
  } else {
    doc.commit = commit;
    doc.commit_time = ctx.commit_time;
    doc.machine = machine;
    doc.cpu_model = ctx.cpu_model;
    doc.hardware_threads = ctx.hardware_threads;
    doc.suite = suite;
  }
  doc.runs.push_back(history_entry(results));
  make_directories(file.parent_path().string());
  write_file_atomic(file.string(), json_text(to_json(doc), 1));
  return file.string();
}

int history_plot(const std::string& dir, const std::string& out) {
  if (!fs::is_directory(dir)) throw InputError(fmt::format("{}: no such history directory", dir));
  // Every file history.py will read (DIR/MACHINE/SUITE/COMMIT.json) is read first as the typed record: one
  // that does not fit is refused here, naming its JSON path.
  bool any = false;
  std::error_code ec;
  for (const auto& machine : fs::directory_iterator(dir, ec))
    for (const auto& suite : fs::directory_iterator(machine.path(), ec))
      for (const auto& f : fs::directory_iterator(suite.path(), ec))
        if (f.path().extension() == ".json") {
          (void)read_history_file(f.path().string());
          any = true;
        }
  if (!any)
    throw InputError(
        fmt::format("{}: no history files (MACHINE/SUITE/COMMIT.json); add runs with growbench history add", dir));
  return run_reports_script("history.py", {dir, "--out", out});
}

}  // namespace growbench
