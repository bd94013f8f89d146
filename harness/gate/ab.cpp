#include "harness/gate/ab.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/json_util.hpp"
#include "harness/output/exporters.hpp"
#include "harness/record/files.hpp"
#include "harness/record/record.hpp"
#include "harness/run/process.hpp"
#include "harness/stats/stats.hpp"
#include "harness/run/trial.hpp"
#include "algorithms/plugins/loader.hpp"

namespace growbench {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kSides[2] = {"A", "B"};

// The absolute paths of the A and B binaries.
using Binaries = std::array<std::string, 2>;

// Samples of one cell: per side, per metric ("growth.wall_s", ...).
using Samples = std::array<std::map<std::string, std::vector<double>>, 2>;

struct Cell {
  const SuiteConfig* config = nullptr;
  fs::path dir;
  Samples pilot, confirmation;  // the first batch (pilot and its extension), the confirmation rerun
  std::string error;            // a trial that failed: the cell is dropped
  std::array<std::string, 2> hash;
};

std::string version_of(const std::string& binary, const fs::path& dir) {
  const std::string log = (dir / "version.txt").string();
  fs::remove(log);
  const ChildResult r = run_program({binary, "--version"}, "", {30.0, 0}, log);
  if (r.exit_code != 0) return "";
  std::string v = read_text_file(log);
  while (!v.empty() && (v.back() == '\n' || v.back() == '\r')) v.pop_back();
  return v;
}

json verdict_json(const TimingVerdict& v) {
  json j = {{"verdict", v.verdict},   {"n_a", v.n_a},      {"n_b", v.n_b},       {"median_a", v.median_a},
            {"median_b", v.median_b}, {"robust_cv", v.cv}, {"needed", v.needed}, {"paired", v.paired}};
  // Each test: its ratio with the bootstrap interval, its statistic, p, and whether p is exact.
  auto test = [&](const std::string& prefix, const RatioInterval& i, const char* statistic, double value, double p,
                  bool exact) {
    j[prefix + "ratio"] = i.ratio;
    j[prefix + "ratio_lo"] = i.lo;
    j[prefix + "ratio_hi"] = i.hi;
    j[prefix + statistic] = value;
    j[prefix + "p"] = p;
    j[prefix + "exact"] = exact;
  };
  test("", v.interval, "u", v.test.u, v.test.p, v.test.exact);
  test("pair_", v.paired_interval, "w_plus", v.paired_test.w_plus, v.paired_test.p, v.paired_test.exact);
  j["pair_robust_cv"] = v.paired_cv;
  return j;
}

// Samples come in pairs (one A and one B per round, side by side): judged paired as well as unpaired.
TimingVerdict judge(const Samples& s, const std::string& metric, const AbOptions& o) {
  return judge_timings(s[0].at(metric), s[1].at(metric), o.effect, o.alpha, true);
}

// How many pairs `s` holds.
int count(const Samples& s) {
  return s[0].empty() ? 0 : static_cast<int>(s[0].begin()->second.size());
}

void check_options(const AbOptions& o) {
  for (const auto& b : {o.a_binary, o.b_binary})
    if (access(b.c_str(), X_OK) != 0)
      throw InputError(fmt::format("ab: '{}' is not an executable growbench binary", b));
  if (!(o.effect > 1.0 && std::isfinite(o.effect)))  // written so that NaN fails too
    throw InputError(fmt::format("ab: --effect must be a finite number above 1, got {}", o.effect));
  if (!(o.alpha > 0.0 && o.alpha < 1.0))
    throw InputError(fmt::format("ab: --alpha must be in (0, 1), got {}", o.alpha));
  if (o.min_repetitions < 3 || o.max_repetitions < o.min_repetitions)
    throw InputError(
        fmt::format("ab: expected 3 <= --min-reps <= --max-reps, got {} and {}", o.min_repetitions, o.max_repetitions));
}

// One cell per suite config, with the spec file each side's trials read.
std::vector<Cell> make_cells(const Suite& suite, const fs::path& out, const std::vector<std::string>& b_plugins) {
  std::vector<Cell> cells;
  for (const auto& c : suite.configs) {
    Cell cell;
    cell.config = &c;
    cell.dir = out / "cells" / c.id;
    for (int s = 0; s < 2; ++s) {
      make_directories((cell.dir / kSides[s]).string());
      json job = trial_job(c, (cell.dir / kSides[s]).string());
      if (s == 1 && !b_plugins.empty()) {
        job["plugins"] = json::array();
        for (const auto& p : b_plugins) job["plugins"].push_back(fs::absolute(p).lexically_normal().string());
      }
      write_file_atomic((cell.dir / kSides[s] / "spec.json").string(), json_text(job, -1));
    }
    cells.push_back(std::move(cell));
  }
  return cells;
}

// The trials of one A/B run: pairs of them alternately, each cell's samples kept in the cell.
class Trials {
 public:
  Trials(const Suite& suite, const AbOptions& o, const Binaries& bins, std::vector<Cell>& cells)
      : suite_(suite), o_(o), bins_(bins), cells_(cells) {
    for (const auto& p : o.phases) {
      metrics_.push_back(p + ".wall_s");
      metrics_.push_back(p + ".cpu_s");
    }
  }
  // What is judged: each phase's wall and CPU time ("growth.wall_s", "growth.cpu_s", ...).
  const std::vector<std::string>& metrics() const { return metrics_; }
  int trials_run() const { return trials_run_; }
  // Clears the progress line.
  void clear_progress() const {
    if (tty_) fmt::print(stderr, "\r{:<100}\r", "");
  }

  // A warm-up pair (file caches, the binaries' pages), not kept.
  void warm_up() {
    if (cells_.empty()) return;
    run_one(cells_.front(), 0, nullptr);
    run_one(cells_.front(), 1, nullptr);
  }

  // A batch: a pilot of min_repetitions pairs, whose noise then sets how many pairs the effect asked for
  // needs (capped at max_repetitions).
  void pilot_then_extend(const std::string& stage, const std::vector<std::size_t>& which, Samples Cell::*into) {
    std::map<std::size_t, int> target;
    for (const std::size_t k : which) target[k] = o_.min_repetitions;
    batch(stage, target, into);
    for (auto& [k, n] : target) {
      if (!cells_[k].error.empty()) continue;
      int need = o_.min_repetitions;
      for (const auto& m : metrics_) need = std::max(need, judge(cells_[k].*into, m, o_).needed);
      n = std::min(need, o_.max_repetitions);
    }
    batch(stage, target, into);
  }

  // The cells whose first batch flags a metric slower or faster.
  std::vector<std::size_t> flagged() const {
    std::vector<std::size_t> flagged;
    for (std::size_t k = 0; k < cells_.size(); ++k) {
      if (!cells_[k].error.empty()) continue;
      bool any = false;
      for (const auto& m : metrics_) {
        const std::string v = judge(cells_[k].pilot, m, o_).verdict;
        any = any || v == "slower" || v == "faster";
      }
      if (any) flagged.push_back(k);
    }
    return flagged;
  }

 private:
  // One trial of one side: its phases' times into `into`, or the cell's error.
  void run_one(Cell& cell, int side, Samples* into) {
    const fs::path dir = cell.dir / kSides[side];
    fs::remove(dir / "record.json");
    const ChildResult r = run_program({bins_[side], "trial", (dir / "spec.json").string()}, "",
                                      {suite_.timeout_s, suite_.memory_limit_bytes}, (dir / "log.txt").string());
    ++trials_run_;
    std::string why;
    if (r.timed_out)
      why = fmt::format("timed out after {} s", suite_.timeout_s);
    else if (r.signal != 0)
      why = "killed by " + signal_name(r.signal);
    else if (r.exit_code != 0 || !fs::exists(dir / "record.json"))
      why = fmt::format("exit code {} (see {})", r.exit_code, (dir / "log.txt").string());
    if (!why.empty()) {
      cell.error = fmt::format("side {} ({}): {}", kSides[side], bins_[side], why);
      return;
    }
    TrialRecord rec;
    try {
      rec = read_trial_record((dir / "record.json").string());
    } catch (const std::exception& e) {
      cell.error = fmt::format("side {}: {}/record.json is unreadable: {}", kSides[side], dir.string(), e.what());
      return;
    }
    cell.hash[static_cast<std::size_t>(side)] = rec.results.geometry_hash;
    if (!into) return;  // a warm-up
    for (const auto& p : o_.phases) {
      const auto phase = phase_named(p);
      const PhaseMeasures* m = phase ? rec.phases.find(*phase) : nullptr;
      if (!m) {
        cell.error = fmt::format("side {}: its record has no phase '{}'", kSides[side], p);
        return;
      }
      (*into)[static_cast<std::size_t>(side)][p + ".wall_s"].push_back(m->wall_s);
      (*into)[static_cast<std::size_t>(side)][p + ".cpu_s"].push_back(m->cpu_s);
    }
  }

  // Runs rounds until each listed cell has its target: in each round a cell runs A then B or B then A,
  // alternating by round and by cell.
  void batch(const std::string& stage, const std::map<std::size_t, int>& target, Samples Cell::*which) {
    for (int round = 0;; ++round) {
      bool any = false;
      for (const auto& [k, n] : target) {
        Cell& cell = cells_[k];
        if (!cell.error.empty() || count(cell.*which) >= n) continue;
        any = true;
        if (!o_.quiet) {
          const std::string line =
              fmt::format("[ab {}] {} pair {}/{}", stage, cell.config->id, count(cell.*which) + 1, n);
          if (tty_)
            fmt::print(stderr, "\r{:<100}", line.substr(0, 100));
          else
            fmt::print(stderr, "{}\n", line);
        }
        const int first = (round + static_cast<int>(k)) % 2;
        run_one(cell, first, &(cell.*which));
        if (cell.error.empty()) run_one(cell, 1 - first, &(cell.*which));
      }
      if (!any) break;
    }
  }

  const Suite& suite_;
  const AbOptions& o_;
  const Binaries& bins_;
  std::vector<Cell>& cells_;
  std::vector<std::string> metrics_;
  const bool tty_ = isatty(STDERR_FILENO) != 0 && !o_.quiet;
  int trials_run_ = 0;
};

// What the table and ab.json say of the cells.
struct Findings {
  json cells = json::array();
  std::string table;
  std::map<std::string, int> tally;
  bool regression = false;
};

// One metric's verdicts: the first batch's, the confirmation's when it ran, and the final word ("final").
json metric_verdict(const Cell& cell, const std::string& m, const TimingVerdict& v, const AbOptions& o) {
  json jm = verdict_json(v);
  std::string final_verdict = v.verdict;
  if (v.verdict == "slower" || v.verdict == "faster") {
    if (count(cell.confirmation) > 0) {
      const TimingVerdict c = judge(cell.confirmation, m, o);
      jm["confirmation"] = verdict_json(c);
      final_verdict = c.verdict == v.verdict ? (v.verdict == "slower" ? "regression" : "improvement") : "not confirmed";
    } else {
      final_verdict = v.verdict + " (unconfirmed)";
    }
  }
  if (final_verdict == "inconclusive" && v.needed > o.max_repetitions)
    jm["note"] =
        fmt::format("noise (robust CV {:.1f}%) needs ~{} repetitions per side for a {:.0f}% effect; the cap is {}",
                    100 * v.cv, v.needed, 100 * (o.effect - 1), o.max_repetitions);
  jm["final"] = final_verdict;
  return jm;
}

// A cell's samples, verdicts and table rows into `f`.
void judge_cell(const Cell& cell, const std::vector<std::string>& metrics, const AbOptions& o, Findings& f) {
  json jc = {{"id", cell.config->id}, {"verdicts", json::object()}};
  for (int s = 0; s < 2; ++s) {
    jc["samples"][kSides[s]] = cell.pilot[static_cast<std::size_t>(s)];
    if (count(cell.confirmation) > 0)
      jc["confirmation_samples"][kSides[s]] = cell.confirmation[static_cast<std::size_t>(s)];
  }
  if (!cell.error.empty()) {
    jc["error"] = cell.error;
    f.table += fmt::format("{:<30} error: {}\n", cell.config->id.substr(0, 30), cell.error);
    ++f.tally["error"];
    f.cells.push_back(jc);
    return;
  }
  jc["same_plant"] = cell.hash[0] == cell.hash[1];
  for (const auto& m : metrics) {
    const TimingVerdict v = judge(cell.pilot, m, o);
    const json jm = metric_verdict(cell, m, v, o);
    const std::string final_verdict = jm["final"].get<std::string>();
    ++f.tally[final_verdict];
    if (final_verdict == "regression") f.regression = true;
    f.table += fmt::format(
        "{:<30} {:<14} {:>3} {:>10} {:>10} {:>22} {:>7.2g} {:>22} {:>7.2g}  {}{}\n", cell.config->id.substr(0, 30), m,
        v.n_a, format_seconds(v.median_a), format_seconds(v.median_b),
        fmt::format("{:.3f} [{:.3f}, {:.3f}]", v.interval.ratio, v.interval.lo, v.interval.hi), v.test.p,
        fmt::format("{:.3f} [{:.3f}, {:.3f}]", v.paired_interval.ratio, v.paired_interval.lo, v.paired_interval.hi),
        v.paired_test.p, final_verdict, jm.contains("note") ? " (" + jm["note"].get<std::string>() + ")" : "");
    jc["verdicts"][m] = jm;
  }
  f.cells.push_back(jc);
}

// The table: a header, the cells' rows, then how to read it and the tally.
// "NAME (xxh3 HASH), ..." for a side's plugins, or nothing.
std::string plugins_line(const char* side, const json& plugins) {
  std::string s;
  for (const auto& p : plugins)
    s += fmt::format("{}{} {} (xxh3 {})", s.empty() ? "" : ", ", p.at("name").get<std::string>(),
                     p.at("path").get<std::string>(), p.at("hash").get<std::string>());
  return s.empty() ? "" : fmt::format("{} plugins: {}\n", side, s);
}

std::string table_of(const Findings& f, const Binaries& bins, const std::array<json, 2>& plugins, int trials_run,
                     const AbOptions& o) {
  std::string table =
      fmt::format("{:<30} {:<14} {:>3} {:>10} {:>10} {:>22} {:>7} {:>22} {:>7}  {}\n", "cell", "metric", "n",
                  "A median", "B median", "B/A [95% CI]", "p MW", "pairs B/A [95% CI]", "p pairs", "verdict");
  table += f.table;
  std::string counts;
  for (const auto& [k, n] : f.tally) counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", n, k);
  table += fmt::format(
      "\nA = {}\nB = {}\n{}{}{} trials in pairs, A B and B A alternately. A metric is flagged when p < {} and the "
      "median "
      "ratio is beyond {:.2f} with its bootstrap 95% interval excluding 1, either for the two samples (Mann-Whitney) "
      "or for "
      "the pairs' ratios (Wilcoxon signed-rank; drift that moves both sides of a pair cancels there); a flagged cell "
      "is "
      "rerun and counts only if the rerun flags it again. 'no change': an interval within [1/{:.2f}, {:.2f}].\n{}\n"
      "verdict: {}\n",
      bins[0], bins[1], plugins_line("A", plugins[0]), plugins_line("B", plugins[1]), trials_run, o.alpha, o.effect,
      o.effect, o.effect, counts, f.regression ? "REGRESSION (B is slower, confirmed)" : "no confirmed regression");
  return table;
}

// The plugins side `s` runs, each with its file's hash, ABI and version: this process's (the suite's and
// --plugin's), or for side B the --plugin-b files when given.
json plugins_of_side(const AbOptions& o, int s) {
  json out = json::array();
  if (s == 1 && !o.b_plugins.empty()) {
    for (const auto& p : o.b_plugins) out.push_back(to_json(describe_plugin(p)));
  } else {
    for (const auto& p : loaded_plugins()) out.push_back(to_json(p));
  }
  return out;
}

// ab.json: what ran, with which binaries, plugins and options, and every cell's samples and verdicts.
json doc_of(Findings&& f, const Suite& suite, const AbOptions& o, const Binaries& bins,
            const std::array<json, 2>& plugins, const fs::path& out, int trials_run) {
  json doc = {{"kind", "growbench-ab"},
              {"schema_version", 1},
              {"suite", {{"name", suite.name}, {"file", suite.file}, {"hash", suite.hash}}},
              {"binaries",
               {{"A", {{"path", bins[0]}, {"version", version_of(bins[0], out)}, {"plugins", plugins[0]}}},
                {"B", {{"path", bins[1]}, {"version", version_of(bins[1], out)}, {"plugins", plugins[1]}}}}},
              {"options",
               {{"effect", o.effect},
                {"alpha", o.alpha},
                {"power", o.power},
                {"min_repetitions", o.min_repetitions},
                {"max_repetitions", o.max_repetitions},
                {"phases", o.phases},
                {"confirm", o.confirm},
                {"b_plugins", o.b_plugins}}},
              {"context", run_context()},
              {"trials_run", trials_run},
              {"cells", std::move(f.cells)}};
  doc["verdict"] = f.regression ? "regression" : "ok";
  doc["tally"] = f.tally;
  return doc;
}

}  // namespace

AbResult run_ab(const Suite& suite, const AbOptions& o) {
  check_options(o);
  const fs::path out = o.out_dir.empty() ? fs::path("out/ab") / suite.name : fs::path(o.out_dir);
  const FolderLock lock = FolderLock::take(out.string(), "ab");
  const Binaries bins = {fs::absolute(o.a_binary).string(), fs::absolute(o.b_binary).string()};
  const std::array<json, 2> plugins = {plugins_of_side(o, 0), plugins_of_side(o, 1)};  // B's checked before trials
  std::vector<Cell> cells = make_cells(suite, out, o.b_plugins);

  Trials trials(suite, o, bins, cells);
  trials.warm_up();
  std::vector<std::size_t> all;
  for (std::size_t k = 0; k < cells.size(); ++k) all.push_back(k);
  trials.pilot_then_extend("main", all, &Cell::pilot);
  // Flagged cells run again, a fresh batch by the same procedure: only a repeated flag counts.
  const std::vector<std::size_t> flagged = trials.flagged();
  if (o.confirm) trials.pilot_then_extend("confirm", flagged, &Cell::confirmation);
  trials.clear_progress();

  Findings f;
  for (const Cell& cell : cells) judge_cell(cell, trials.metrics(), o, f);
  AbResult res;
  res.regression = f.regression;
  res.table = table_of(f, bins, plugins, trials.trials_run(), o);
  res.doc = doc_of(std::move(f), suite, o, bins, plugins, out, trials.trials_run());
  write_file_atomic((out / "ab.json").string(), json_text(res.doc, 1));
  return res;
}

}  // namespace growbench
